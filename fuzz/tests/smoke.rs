//! The fuzz engine itself, briefly, inside `make test`: a few hundred
//! mutated inputs per target must neither panic nor hang, and the mutations
//! must really mutate (some inputs rejected) without always breaking the
//! file (some accepted).

use std::time::Duration;

use slotforge_fuzz::{load_seeds, run, workspace_root, Config, Target};

fn campaign(target: Target, count: u64) {
    let root = workspace_root();
    let seeds = load_seeds(target, &root).unwrap();
    let crashes = tempfile_dir(target);
    let cfg = Config {
        target,
        count,
        seed: 0x5eed,
        timeout: Duration::from_secs(20),
        crashes: crashes.clone(),
        verbose: true,
        max_hangs: 1,
    };
    let sum = run(&cfg, seeds);
    eprintln!("{sum}");
    let _ = std::fs::remove_dir_all(&crashes);
    assert_eq!(sum.inputs, count);
    assert!(
        sum.crashes.is_empty(),
        "{:#?}",
        sum.crashes
            .iter()
            .map(|c| (&c.kind, &c.message, &c.ops))
            .collect::<Vec<_>>()
    );
    assert!(sum.rejected > count / 4, "{sum}");
    assert!(sum.ok + sum.diverged > 0, "{sum}");
}

fn tempfile_dir(t: Target) -> std::path::PathBuf {
    std::env::temp_dir().join(format!(
        "slotforge-fuzz-smoke-{}-{}",
        t.name(),
        std::process::id()
    ))
}

#[test]
fn mix_engine_smoke() {
    campaign(Target::Mix, 300);
}

#[test]
fn vcd_engine_smoke() {
    campaign(Target::Vcd, 300);
}

#[test]
fn inputs_are_reproducible() {
    let root = workspace_root();
    let seeds = load_seeds(Target::Mix, &root).unwrap();
    for i in [0, 7, 299] {
        let a = slotforge_fuzz::input(Target::Mix, &seeds, 42, i);
        let b = slotforge_fuzz::input(Target::Mix, &seeds, 42, i);
        assert_eq!(a, b);
        assert_ne!(a.1, seeds[a.0].bytes, "input {i} is not mutated");
    }
}
