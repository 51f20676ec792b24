//! The two comment lines of an OBJ that the program reads:
//! `# camera eye X Y Z target X Y Z up X Y Z fov DEG`, `# patch-size S` and `# keep-faces` (every
//! face its own polygon: the Table 1 rooms, whose face counts are the paper's).

use super::error::SceneError;
use super::files::shown_path;
use super::Camera;
use glam::Vec3;
use std::path::Path;

/// What a scene's comments set.
#[derive(Debug, Default)]
pub(super) struct Header {
    pub camera: Option<Camera>,
    pub patch_size: Option<f32>,
    /// `# keep-faces`: every face its own polygon (no merging of coplanar faces).
    pub keep_faces: bool,
}

/// The words a camera line is made of: a comment that begins `# camera` and goes on with
/// another word is an ordinary comment.
const CAMERA_WORDS: [&str; 4] = ["eye", "target", "up", "fov"];

pub(super) fn parse_header(path: &Path, text: &str) -> Result<Header, SceneError> {
    let mut header = Header::default();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if !line.starts_with('#') {
            continue;
        }
        let bad = |what: &str| SceneError::Parse {
            path: shown_path(path),
            line: format!(":{}", n + 1),
            what: what.to_string(),
        };
        if let Some(rest) = line.strip_prefix("# camera") {
            if !rest
                .split_whitespace()
                .next()
                .is_some_and(|w| CAMERA_WORDS.contains(&w))
            {
                continue;
            }
            let camera = parse_camera(rest).ok_or_else(|| {
                bad("expected `# camera eye X Y Z target X Y Z up X Y Z fov DEG`")
            })?;
            camera
                .validate()
                .map_err(|e| bad(&format!("bad `# camera` line: {e}")))?;
            header.camera = Some(camera);
        } else if line == "# keep-faces" {
            header.keep_faces = true;
        } else if let Some(rest) = line.strip_prefix("# patch-size") {
            let s: f32 = rest
                .trim()
                .parse()
                .map_err(|_| bad("expected `# patch-size S`"))?;
            if !(s > 0.0 && s.is_finite()) {
                return Err(bad("the patch size must be a positive number"));
            }
            header.patch_size = Some(s);
        }
    }
    Ok(header)
}

fn parse_camera(rest: &str) -> Option<Camera> {
    let tokens: Vec<&str> = rest.split_whitespace().collect();
    let mut camera = Camera {
        eye: Vec3::ZERO,
        target: Vec3::Z,
        up: Vec3::Y,
        fov_y: 40.0,
    };
    let mut seen = 0;
    let mut i = 0;
    let num = |s: &str| s.parse::<f32>().ok().filter(|v| v.is_finite());
    while i < tokens.len() {
        let vec = |i: usize| -> Option<Vec3> {
            Some(Vec3::new(
                num(tokens.get(i + 1)?)?,
                num(tokens.get(i + 2)?)?,
                num(tokens.get(i + 3)?)?,
            ))
        };
        match tokens[i] {
            "eye" => camera.eye = vec(i)?,
            "target" => camera.target = vec(i)?,
            "up" => camera.up = vec(i)?,
            "fov" => {
                camera.fov_y = num(tokens.get(i + 1)?)?;
                seen |= 8;
                i += 2;
                continue;
            }
            _ => return None,
        }
        seen |= match tokens[i] {
            "eye" => 1,
            "target" => 2,
            _ => 4,
        };
        i += 4;
    }
    (seen & 3 == 3).then_some(camera)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_and_patch_size_lines() {
        let h = parse_header(
            Path::new("s.obj"),
            "# camera position chosen by hand\r\n\t# camera eye 0 1 -5 target 0 1 0 up 0 1 0 \
             fov 50\r\n# patch-size 0.25\r\n",
        )
        .unwrap();
        let c = h.camera.unwrap();
        assert_eq!((c.eye, c.fov_y), (Vec3::new(0.0, 1.0, -5.0), 50.0));
        assert_eq!(h.patch_size, Some(0.25));
        let e = parse_header(
            Path::new("s.obj"),
            "v 0 0 0\n# camera eye 0 0 0 target 0 0\n",
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("s.obj:2: expected `# camera"), "{e}");
    }
}
