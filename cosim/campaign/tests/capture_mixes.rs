//! Issue 17's judgement on unseen mixes: captures of the gateware (hdl's
//! RtlSim) of random mixes (`campaign::mixgen`), as a logic analyser records
//! them (resampled at 24 and 100 MHz with an arbitrary phase, from the
//! middle of a frame, no clock or reset, channels D0..Dn), pass the
//! time-level check as sigrok `.sr` sessions and as sigrok-cli's VCD (and
//! by an analyser some ppm off the design's clock); the
//! same captures of mutated gateware (a design-level fault of every class
//! built in, and faults made on the recorded pins) fail.

use std::path::Path;

use judge::check_capture;

use crate::tools;
use testkit::analyser;

use analyser::{capture, check, lanes, mutate, resample, run, to_sigrok, Mutation};

/// The first `n` random mixes from `seed` on that synthesize, fit the pin
/// contract and convert on every branch.
fn mixes(seed: u64, n: usize) -> Vec<(u64, lut_gen::Schedule)> {
    let mut v = Vec::new();
    let mut k = seed;
    while v.len() < n {
        k += 1;
        let text = campaign::random_mix(k, &campaign::Shape::default());
        let Ok(mix) = lut_gen::parse(Path::new("random.toml"), &text) else {
            continue;
        };
        let Ok(s) = lut_gen::synthesize(&mix) else {
            continue;
        };
        if lut_gen::Layout::fits(&s).is_err()
            || (0..s.branches.len()).any(|b| s.branch_instants_in_frame(b).is_empty())
        {
            continue;
        }
        v.push((k, s));
    }
    v
}

/// `classes`: how many design-level fault classes to build in per mix.
fn captures_of_random_mixes(seed: u64, n: usize, classes: usize) {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    for (k, s) in mixes(seed, n) {
        let f = s.grid.frame_cycles;
        // Over two frame boundaries: a branch may start converting late in
        // the window, and a fault of the frame's length shows at a boundary.
        let window = (f * 37 / 100 + k % 97, f * 293 / 100);
        let mut dut = engines::RustHdlDut::new(&s).unwrap();
        let clean = run(&s, &mut dut, 3);
        let (_, map) = lanes(&s);
        // 100 MHz and 24 MHz analysers, their phases drawn from the seed.
        for (ts, phase) in [
            (10_000, 1_000 + k * 7_919 % 9_000),
            (41_667, k * 104_729 % 41_000),
        ] {
            let v = d.path().join(format!("clean{k}-{ts}.vcd"));
            let (sr, back) = capture(&s, &clean, window, (ts, phase), &v);
            for file in [&sr, &back] {
                let r = check(&s, &map, file);
                assert!(
                    r.ok,
                    "mix {k}, {} at {ts} ps: {}",
                    file.display(),
                    r.summary()
                );
                assert!(r.edges_checked > 20, "mix {k}: {}", r.summary());
            }
        }
        // An analyser off the design's clock by up to ±300 ppm, as crystals
        // are: passes, the offset measured within its stated uncertainty.
        let ppm = (20 + k * 37 % 280) as f64 * if k % 2 == 0 { 1.0 } else { -1.0 };
        let v = d.path().join(format!("drift{k}.vcd"));
        let r = analyser::check_drifting(&s, &clean, window, (10_000, 2_345), ppm, &v);
        assert!(r.ok, "mix {k} at {ppm} ppm: {}", r.summary());
        if let Some(got) = r.clock_ppm {
            let span_ps = (window.1 - window.0) as f64 * 1e12 / s.mix.clock_hz as f64;
            let err_ps = (got + ppm).abs() * 1e-6 * span_ps;
            assert!(
                err_ps <= r.clock_uncertainty_ps as f64 + 1.0,
                "mix {k} at {ppm} ppm: {}",
                r.summary()
            );
        }
        // Mutated gateware: one design-level fault of every class.
        let reference = d.path().join(format!("ref{k}.vcd"));
        resample(&s, &clean, window.0, window.1, 10_000, 3_333, &reference);
        let faults = campaign::one_gateware_fault_per_class(&s);
        assert!(!faults.is_empty(), "mix {k}: no gateware fault");
        for (class, fault) in faults.into_iter().take(classes) {
            let Ok(mut bad) = campaign::gateware_dut(&s, fault) else {
                continue;
            };
            let pins = run(&s, &mut bad, 3);
            let v = d.path().join(format!("{class}{k}.vcd"));
            resample(&s, &pins, window.0, window.1, 10_000, 3_333, &v);
            // A fault that leaves every captured lane as the clean run has
            // it (e.g. a slice counter one short in a mix whose slices are
            // alike) cannot fail any capture: the analyser saw the same.
            if std::fs::read(&v).unwrap() == std::fs::read(&reference).unwrap() {
                eprintln!("mix {k}: {class}: the captured lanes equal the clean run's");
                continue;
            }
            let (sr, _) = to_sigrok(&v, 10_000);
            let lanes = judge::parse_map(&map, &s).unwrap();
            let cap = judge::read_capture(&sr, lanes).unwrap();
            // A design fault may break the phase everywhere (an input
            // problem only if nothing fits at all), never pass.
            match check_capture(&s, &cap, 0) {
                Ok(r) => assert!(
                    !r.ok,
                    "mix {k}: {class} ({fault:?}) passed: {}",
                    r.summary()
                ),
                Err(e) => panic!("mix {k}: {class} ({fault:?}): not judged: {e}"),
            }
        }
        // Faults on the recorded pins, named by class.
        let mid = (window.0 + window.1) / 2;
        for (m, want) in Mutation::PINS {
            // A mix whose muxes never switch (one channel a branch) has
            // no mux change to move.
            let switches = clean[mid as usize..]
                .windows(2)
                .any(|w| w[0].mux_sel != w[1].mux_sel || w[0].mux_en != w[1].mux_en);
            if matches!(m, Mutation::MuxEarly) && !switches {
                continue;
            }
            let mut bad = clean.clone();
            mutate(&s, &mut bad, m, mid);
            let v = d.path().join(format!("{m:?}{k}.vcd"));
            let (sr, _) = capture(&s, &bad, window, (41_667, 12_345), &v);
            let r = check(&s, &map, &sr);
            assert!(!r.ok, "mix {k}: {m:?} passed: {}", r.summary());
            assert!(
                r.violations.iter().any(|v| v.rule.contains(want)),
                "mix {k}: {m:?}: {}",
                r.summary()
            );
        }
    }
}

/// One unseen random mix and one gateware fault class (the default suite:
/// seconds).
#[test]
fn analyser_captures_of_a_random_mix_pass_and_mutants_fail() {
    captures_of_random_mixes(1_000, 1, 1);
}

/// Ten more mixes, every gateware fault class in each.
#[test]
#[ignore = "long: make test-long"]
fn analyser_captures_of_ten_random_mixes_every_gateware_fault() {
    captures_of_random_mixes(2_000, 10, usize::MAX);
}
