//! The ranges of the numeric flags, checked while parsing so that a bad value ends the run with
//! clap's usage error (exit status 2) and the range in the message, before anything is solved.
//! The ranges are listed in docs/usage.md.

use crate::display::smooth::MAX_ANGLE;
use crate::scene::{Emission, FOV_RANGE, MAX_KE};
use glam::Vec3;

/// Most shots a solve may ask for: the bench's own cap; more only spins on a solve that has
/// stopped converging.
pub const MAX_SHOTS: u32 = 1_000_000;
/// Most patches: 12× the complex room's 86,077. On llvmpipe one accurate-mode shot of the Cornell
/// box at 1M patches already takes minutes (an emitter shoots from each of its patches).
pub const MAX_PATCHES: u32 = 1 << 20;
/// Item-buffer side: below 16 the pixels are coarser than any scene; 4096 is 16× the accurate
/// mode's default. The GL limits are checked too (the hemicube's buffer is five faces wide).
pub const MIN_HEMI_RES: u32 = 16;
pub const MAX_HEMI_RES: u32 = 4096;

/// `--hemi-res`: [`MIN_HEMI_RES`] to [`MAX_HEMI_RES`].
pub fn hemi_res() -> clap::builder::RangedI64ValueParser<u32> {
    clap::value_parser!(u32).range(MIN_HEMI_RES as i64..=MAX_HEMI_RES as i64)
}
/// An item-buffer resolution that may be off: 0, or as [`hemi_res`].
pub fn hemi_res_or_off(s: &str) -> Result<u32, String> {
    let v: i64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a whole number"))?;
    if v == 0 || (MIN_HEMI_RES as i64..=MAX_HEMI_RES as i64).contains(&v) {
        Ok(v as u32)
    } else {
        Err(format!(
            "{s} is neither 0 (off) nor in {MIN_HEMI_RES}..={MAX_HEMI_RES}"
        ))
    }
}

/// Shooter and emitter cells, in patches: 16384 is the widest atlas, so a larger cell is the
/// whole polygon anyway.
pub const MAX_CELL: u32 = 16_384;
/// Shortest tessellation edge, in patch sizes: below it the triangle count grows as 1/K² (at
/// 1e-9 the solve never starts).
pub const MIN_TESSELLATION: f32 = 0.5;
/// Most repeats of a bench measurement.
pub const MAX_REPEAT: u32 = 1000;

fn number(s: &str) -> Result<f32, String> {
    s.trim()
        .parse::<f32>()
        .map_err(|_| format!("'{s}' is not a number"))
}

/// The stopping rule's threshold: 0 < t < 1.
pub fn threshold(s: &str) -> Result<f32, String> {
    let t = number(s)?;
    if t > 0.0 && t < 1.0 {
        Ok(t)
    } else {
        Err(format!("{s} is outside 0 < F < 1"))
    }
}

/// A share: 0 ≤ F < 1.
pub fn share(s: &str) -> Result<f32, String> {
    let v = number(s)?;
    if (0.0..1.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{s} is outside 0 ≤ F < 1"))
    }
}

/// A finite number greater than 0 (exposure, patch size).
pub fn positive(s: &str) -> Result<f32, String> {
    let v = number(s)?;
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{s} must be a finite number greater than 0"))
    }
}

/// Vertical field of view, degrees, within [`FOV_RANGE`].
pub fn fov(s: &str) -> Result<f32, String> {
    let v = number(s)?;
    if FOV_RANGE.contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "{s} is outside {} to {} degrees",
            FOV_RANGE.start(),
            FOV_RANGE.end()
        ))
    }
}

/// The smooth shading's crease angle, degrees: 0 (off) up to [`MAX_ANGLE`] (excluded).
pub fn smooth_angle(s: &str) -> Result<f32, String> {
    let v = number(s)?;
    if (0.0..MAX_ANGLE).contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "{s} is outside 0 ≤ DEG < {MAX_ANGLE} degrees (0: no smoothing; at {MAX_ANGLE} a box's \
             corners would be averaged)"
        ))
    }
}

/// Tessellation: 0 (off), or at least [`MIN_TESSELLATION`] patch sizes.
pub fn tessellation(s: &str) -> Result<f32, String> {
    let v = number(s)?;
    if v == 0.0 || (v >= MIN_TESSELLATION && v.is_finite()) {
        Ok(v)
    } else {
        Err(format!(
            "{s} must be 0 (off) or a finite number of patch sizes from {MIN_TESSELLATION} up"
        ))
    }
}

/// `--emit NAME=R,G,B`: a material name (everything before the last `=`) and an emitted
/// radiance of three numbers in [0, [`MAX_KE`]].
pub fn emission(s: &str) -> Result<Emission, String> {
    let usage = || format!("expected NAME=R,G,B (a material and its emitted radiance), got '{s}'");
    let (name, rgb) = s.rsplit_once('=').ok_or_else(usage)?;
    if name.is_empty() {
        return Err(usage());
    }
    let v: Vec<f32> = rgb
        .split(',')
        .map(|t| t.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| usage())?;
    match v[..] {
        [r, g, b] if v.iter().all(|c| (0.0..=MAX_KE).contains(c)) => Ok(Emission {
            material: name.to_string(),
            ke: [r, g, b],
        }),
        [_, _, _] => Err(format!(
            "the radiance in '{s}' must be three numbers from 0 to {MAX_KE:e}"
        )),
        _ => Err(usage()),
    }
}

/// `--sky R,G,B`: the sky's radiance, three numbers in [0, [`MAX_KE`]], not all 0.
pub fn sky(s: &str) -> Result<Vec3, String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|t| t.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("expected R,G,B (the sky's radiance), got '{s}'"))?;
    match v[..] {
        [r, g, b] if v.iter().all(|c| (0.0..=MAX_KE).contains(c)) && r.max(g).max(b) > 0.0 => {
            Ok(Vec3::new(r, g, b))
        }
        _ => Err(format!(
            "the sky's radiance '{s}' must be three numbers from 0 to {MAX_KE:e}, not all 0"
        )),
    }
}

/// Most CPU worker threads: 4 per core. More threads than cores only add switching; at 1024 on
/// two cores a 20-shot Cornell solve took over two minutes instead of 5 s.
pub fn max_threads() -> usize {
    4 * std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// CPU worker threads: 0 (one per core) to [`max_threads`].
pub fn threads(s: &str) -> Result<usize, String> {
    let n: usize = s
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a whole number"))?;
    let max = max_threads();
    if n <= max {
        Ok(n)
    } else {
        Err(format!(
            "{n} is more than {max} (4 per core on this machine; 0 means one per core)"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges() {
        assert!(threshold("0.5").is_ok());
        for bad in ["0", "1", "nan", "-0.1", "inf", "x"] {
            assert!(threshold(bad).is_err(), "{bad}");
        }
        assert!(positive("1e-3").is_ok());
        for bad in ["0", "-1", "nan", "inf"] {
            assert!(positive(bad).is_err(), "{bad}");
        }
        assert!(fov("1").is_ok() && fov("179").is_ok());
        for bad in ["0", "180", "nan", "-50", "0.5"] {
            assert!(fov(bad).is_err(), "{bad}");
        }
        assert!(tessellation("0").is_ok() && tessellation("2").is_ok());
        for bad in ["1e-9", "-1", "nan", "inf"] {
            assert!(tessellation(bad).is_err(), "{bad}");
        }
        assert!(smooth_angle("0").is_ok() && smooth_angle("89.9").is_ok());
        for bad in ["90", "-1", "nan", "inf", "x"] {
            assert!(smooth_angle(bad).is_err(), "{bad}");
        }
        assert!(threads("0").is_ok() && threads(&max_threads().to_string()).is_ok());
        assert!(threads(&(max_threads() + 1).to_string()).is_err());
        assert!(threads("-1").is_err());
        let e = emission("Light = 1=17,12,4").unwrap();
        assert_eq!(
            (e.material.as_str(), e.ke),
            ("Light = 1", [17.0, 12.0, 4.0])
        );
        assert_eq!(emission("Glass=0,0,0").unwrap().ke, [0.0; 3]);
        for bad in [
            "Glass",
            "=1,1,1",
            "Glass=1,1",
            "Glass=1,1,1,1",
            "Glass=a,1,1",
        ] {
            assert!(emission(bad).unwrap_err().contains("NAME=R,G,B"), "{bad}");
        }
        for bad in [
            "Glass=-1,1,1",
            "Glass=nan,1,1",
            "Glass=inf,1,1",
            "Glass=1e16,1,1",
        ] {
            assert!(
                emission(bad).unwrap_err().contains("from 0 to 1e15"),
                "{bad}"
            );
        }
    }
}
