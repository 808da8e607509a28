//! Writes the feature matrix's mixes (`testkit::matrix`) into a folder, one
//! TOML per point, to run by hand: `cargo run -p testkit --example
//! matrix_mixes -- DIR [N [SEED0]]`: the pairwise cover, N free draws,
//! point `i` seeded `SEED0 + i` (the wide test's seeds: 100), else the
//! pairwise points `1 + i` and the free ones `100 + i`.
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dir = std::path::PathBuf::from(args.first().map_or("matrix", String::as_str));
    std::fs::create_dir_all(&dir).unwrap();
    let mut pts = testkit::matrix::pairwise(1);
    let extra: usize = args.get(1).and_then(|n| n.parse().ok()).unwrap_or(0);
    pts.extend(testkit::matrix::random(2, extra));
    let seed0: Option<u64> = args.get(2).and_then(|n| n.parse().ok());
    for (i, p) in pts.iter().enumerate() {
        let seed = if let Some(s0) = seed0 {
            s0 + i as u64
        } else if i < testkit::matrix::pairwise(1).len() {
            1 + i as u64
        } else {
            100 + i as u64
        };
        let path = dir.join(format!("matrix-{seed}.toml"));
        std::fs::write(&path, testkit::matrix::mix(p, seed)).unwrap();
        println!("{} {p:?}", path.display());
    }
}
