//! The engines on a sample of the quick campaign (`campaign::methods`,
//! `build`'s default speed chart): a fixed sample per mix, one fault of each
//! pin class, run through rust-hdl and Verilator under the same checker;
//! what an engine misses is counted, not an error.

use std::path::Path;

use campaign::{methods, methods_sample, Engine};

use crate::tools;

fn schedule(text: &str) -> Option<lut_gen::Schedule> {
    let mix = lut_gen::parse(Path::new("random.toml"), text).ok()?;
    let s = lut_gen::synthesize(&mix).ok()?;
    let fits = lut_gen::Layout::fits(&s).is_ok()
        && (0..s.branches.len()).all(|b| !s.branch_instants_in_frame(b).is_empty());
    fits.then_some(s)
}

fn tiny() -> lut_gen::Schedule {
    lut_gen::synthesize(&lut_gen::load(&testkit::mix("tiny")).unwrap()).unwrap()
}

/// Random mixes and a shared test mix: the sample is one fault per class,
/// the same each time for one mix; every engine runs it and the checker
/// catches every fault that landed.
#[test]
fn every_engine_runs_the_sample_and_catches_it() {
    let mut mixes: Vec<lut_gen::Schedule> = (300..340)
        .filter_map(|k| schedule(&campaign::random_mix(k, &campaign::Shape::default())))
        .take(2)
        .collect();
    mixes.push(tiny());
    let verilator = tools::require_tool("verilator");
    for s in &mixes {
        let (site, faults) = methods_sample(s);
        assert_eq!(site.name, "mid-frame");
        let classes: std::collections::BTreeSet<_> = faults.iter().map(|f| f.class()).collect();
        assert_eq!(classes.len(), faults.len(), "one fault per class");
        let all: std::collections::BTreeSet<_> =
            judge::PinFault::all(s).iter().map(|f| f.class()).collect();
        assert_eq!(classes, all, "every class of the quick campaign");
        assert_eq!(methods_sample(s).1, faults, "the same sample each time");
        let mut plan = vec![(Engine::Rusthdl, 2)];
        if verilator {
            plan.push((Engine::Verilator, 4));
        }
        let rows = methods(s, &plan, 2);
        assert_eq!(rows.len(), plan.len());
        for (r, (e, n)) in rows.iter().zip(&plan) {
            assert_eq!(r.engine, *e);
            assert!(r.not_run.is_none(), "{r:?}");
            assert!(r.faults_run > 0 && r.faults_run <= *n as u64, "{r:?}");
            assert_eq!(r.caught, r.faults_run, "{}: {r:?}", s.mix.name);
            assert!(r.missed.is_empty() && r.seconds > 0.0, "{r:?}");
        }
    }
}

/// Two mixes of different names order their samples apart (the order is
/// seeded by the name), and a plan of nothing runs nothing.
#[test]
fn the_sample_is_seeded_by_the_mix() {
    let s = tiny();
    let mut renamed = lut_gen::load(&testkit::mix("tiny")).unwrap();
    let orders: std::collections::BTreeSet<Vec<String>> = ["a", "b", "c", "d", "e"]
        .iter()
        .map(|n| {
            renamed.name = format!("tiny-{n}");
            let r = lut_gen::synthesize(&renamed).unwrap();
            methods_sample(&r).1.iter().map(|f| f.name()).collect()
        })
        .collect();
    assert!(orders.len() > 1, "{orders:?}");
    assert!(methods(&s, &[], 2).is_empty());
}
