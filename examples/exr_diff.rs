//! Two lightmap.exr files of one scene compared texel by texel (RGB mean radiance of the texels
//! with any radiance in A): median, 90th, 99th percentile relative difference, and the sums.
//! `cargo run --release --example exr_diff -- A.exr B.exr`
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let read = |p: &str| image::open(p).expect("an EXR").into_rgba32f();
    let (a, b) = (read(&args[1]), read(&args[2]));
    assert_eq!(a.dimensions(), b.dimensions());
    let mean = |p: &image::Rgba<f32>| (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0;
    let (mut sa, mut sb, mut d) = (0f64, 0f64, Vec::new());
    let mut peak = 0f64;
    for (pa, pb) in a.pixels().zip(b.pixels()) {
        let (x, y) = (mean(pa), mean(pb));
        peak = peak.max(x);
        if x > 0.0 || y > 0.0 {
            sa += x;
            sb += y;
            d.push(((y - x).abs(), x));
        }
    }
    let mut rel: Vec<f64> = d.iter().map(|&(e, x)| e / x.max(1e-3 * peak)).collect();
    rel.sort_by(f64::total_cmp);
    let mut abs: Vec<f64> = d.iter().map(|&(e, _)| e / peak).collect();
    abs.sort_by(f64::total_cmp);
    let q = |v: &[f64], f: f64| 100.0 * v[((v.len() - 1) as f64 * f) as usize];
    println!(
        "{} texels; relative: median {:.3} %, 90th {:.3} %, 99th {:.3} %; of the brightest: 99th {:.3} %, max {:.3} %; sum B/A − 1 = {:+.4} %",
        d.len(),
        q(&rel, 0.5),
        q(&rel, 0.9),
        q(&rel, 0.99),
        q(&abs, 0.99),
        q(&abs, 1.0),
        100.0 * (sb / sa - 1.0)
    );
}
