//! Synthesis + audit of large mixes: 100 channels per branch at harmonic
//! rates (40 x 100 Hz, 40 x 500 Hz, 20 x 1 kHz), from 10 to 100 branches
//! (1k to 10k channels).  `cargo bench -p lut-gen --features bench --bench synthesis`.
//!
//! `presets`: `synthesize` alone on every preset in `mixes/`, the
//! 1 024-channel mix, and the mix the exact search used to miss (its time is
//! the search's: first-fit fails on it).  Before/after a change of the
//! synthesizer: `-- presets --save-baseline before` on the old code, then
//! `-- presets --baseline before` on the new (criterion prints the ratio).

use std::fmt::Write;
use std::path::Path;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};

fn big_mix(branches: usize) -> lut_gen::Mix {
    let mut t = String::from(
        "name = \"big\"\n[clock]\nhz = 48_000_000\n[frame]\nperiod_us = 10_000\nslice_us = 1_000\n",
    );
    for b in 0..branches {
        let _ = write!(
            t,
            "[[branch]]\nname = \"b{b}\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = 13\n"
        );
    }
    for b in 0..branches {
        for i in 0..100 {
            let rate = match i {
                0..=39 => 100,
                40..=79 => 500,
                _ => 1_000,
            };
            let _ = write!(
                t,
                "[[channel]]\nname = \"b{b}c{i}\"\nbranch = \"b{b}\"\nrate_hz = {rate}\n"
            );
        }
    }
    lut_gen::parse(Path::new("big.toml"), &t).expect("bench mix parses")
}

fn synthesis_and_audit(c: &mut Criterion) {
    let mut g = c.benchmark_group("synthesize+audit");
    g.sample_size(10);
    for branches in [10usize, 30, 100] {
        let mix = big_mix(branches);
        g.throughput(Throughput::Elements(mix.channels.len() as u64));
        g.bench_with_input(
            BenchmarkId::from_parameter(mix.channels.len()),
            &mix,
            |b, mix| {
                b.iter(|| {
                    let s = lut_gen::synthesize(mix).expect("feasible");
                    lut_gen::AuditReport::of_schedule(&s)
                })
            },
        );
    }
    g.finish();
}

fn presets(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut mixes: Vec<(String, lut_gen::Mix)> = std::fs::read_dir(root.join("mixes"))
        .expect("mixes/")
        .map(|e| e.expect("mixes/ entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| {
            let name = p.file_stem().unwrap().to_string_lossy().into_owned();
            (name, lut_gen::load(&p).expect("preset loads"))
        })
        .collect();
    mixes.sort_by(|a, b| a.0.cmp(&b.0));
    let ch1024 = root.join("hdl/tests/data/ch1024.toml");
    mixes.push((
        "ch1024".into(),
        lut_gen::load(&ch1024).expect("ch1024 loads"),
    ));
    // The mix the old exact search called infeasible (`tests/data/missed.toml`).
    let missed = root.join("lut-gen/tests/data/missed.toml");
    mixes.push((
        "missed".into(),
        lut_gen::load(&missed).expect("missed loads"),
    ));
    let mut g = c.benchmark_group("presets");
    g.sample_size(10);
    for (name, mix) in &mixes {
        // The result is not asserted: the old search gave up on `missed`.
        g.bench_with_input(BenchmarkId::from_parameter(name), mix, |b, mix| {
            b.iter(|| lut_gen::synthesize(mix).is_ok())
        });
    }
    g.finish();
}

criterion_group!(benches, synthesis_and_audit, presets);
criterion_main!(benches);
