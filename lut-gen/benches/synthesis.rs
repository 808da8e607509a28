//! Synthesis + audit of large mixes: 100 channels per branch at harmonic
//! rates (40 x 100 Hz, 40 x 500 Hz, 20 x 1 kHz), from 10 to 100 branches
//! (1k to 10k channels).  `cargo bench -p lut-gen --bench synthesis`.

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

criterion_group!(benches, synthesis_and_audit);
criterion_main!(benches);
