//! `cargo run --release -p hdl --example simbench -- [MIX.toml] [CYCLES]`:
//! RtlSim throughput (cycles per second).
use std::path::Path;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mix = args
        .get(1)
        .map(String::as_str)
        .unwrap_or("mixes/eskin34.toml");
    let cycles: u64 = args
        .get(2)
        .and_then(|x| x.parse().ok())
        .unwrap_or(2_000_000);
    let s = lut_gen::synthesize(&lut_gen::load(Path::new(mix)).expect("mix")).expect("feasible");
    let mut sim = hdl::RtlSim::new(&s).expect("gateware");
    sim.step(true, 0);
    let t0 = Instant::now();
    let mut samples = 0u64;
    let mut miso = 0u64;
    for c in 0..cycles {
        let p = sim.step(false, miso);
        samples += p.sample_valid as u64;
        miso = (c as u8).wrapping_mul(37) as u64 ^ p.sclk as u64;
    }
    let dt = t0.elapsed().as_secs_f64();
    println!(
        "{}: {cycles} cycles in {dt:.2} s = {:.0} cycles/s ({samples} samples, {:.2} passes/cycle)",
        s.mix.name,
        cycles as f64 / dt,
        sim.passes() as f64 / cycles as f64
    );
}
