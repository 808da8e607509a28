//! `check` of a large VCD against the `wellen` crate's load of the same file
//! (header, body and every signal; multi-threaded, as a viewer loads it),
//! measured side by side in one run, with the peak memory of each in a
//! child process of its own.  Usage:
//! `cargo bench -p judge --bench check_vs_wellen -- [FRAMES]` (default 4
//! frames of eskin34, about 130 MB).

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use judge::write_run;
use judge::{ModelDut, RunOptions};

fn schedule() -> lut_gen::Schedule {
    let mix = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../mixes/eskin34.toml");
    lut_gen::synthesize(&lut_gen::load(&mix).unwrap()).unwrap()
}

/// Peak resident memory of this process so far, in MB.
fn peak_mb() -> f64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    s.lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map(|kb| kb / 1024.0)
        .unwrap_or(0.0)
}

/// CPU seconds (user + system, every thread) of this process so far: on a
/// shared machine the wall time depends on the other jobs, the work not.
fn cpu_s() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // The fields after the command name (which may hold spaces).
    let rest = s.rsplit_once(')').map(|x| x.1).unwrap_or("");
    let f: Vec<f64> = rest
        .split_whitespace()
        .map(|x| x.parse().unwrap_or(0.0))
        .collect();
    // utime and stime are fields 14 and 15 of the line, in clock ticks.
    f.get(11)
        .zip(f.get(12))
        .map_or(0.0, |(u, s)| (u + s) / 100.0)
}

/// Child mode: do one job on `path`, print "seconds peak_mb cpu_seconds".
fn child(job: &str, path: &Path) {
    let s = schedule();
    let cpu0 = cpu_s();
    let t = Instant::now();
    match job {
        "check" => {
            let r = judge::check_vcd(&s, path, None).unwrap();
            assert!(r.ok, "{}", r.summary());
        }
        "wellen" => {
            let opts = wellen::LoadOptions {
                multi_thread: true,
                remove_scopes_with_empty_name: false,
            };
            let mut w = wellen::simple::read_with_options(path, &opts).unwrap();
            let h = w.hierarchy();
            let refs: Vec<wellen::SignalRef> = h.all_vars().map(|v| h[v].signal_ref()).collect();
            w.load_signals_multi_threaded(&refs);
        }
        _ => panic!("unknown job {job}"),
    }
    println!(
        "{} {} {}",
        t.elapsed().as_secs_f64(),
        peak_mb(),
        cpu_s() - cpu0
    );
}

/// (wall seconds, peak MB, CPU seconds) of one job in a child process.
fn run(job: &str, path: &Path) -> (f64, f64, f64) {
    let out = Command::new(std::env::current_exe().unwrap())
        .args(["--child", job])
        .arg(path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut it = text.split_whitespace().map(|x| x.parse::<f64>().unwrap());
    (it.next().unwrap(), it.next().unwrap(), it.next().unwrap())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let Some(i) = args.iter().position(|a| a == "--child") {
        child(&args[i + 1], Path::new(&args[i + 2]));
        return;
    }
    let frames: u64 = args.iter().find_map(|a| a.parse().ok()).unwrap_or(4);
    let s = schedule();
    let dir = tempfile::tempdir().unwrap();
    let mut sizes = Vec::new();
    // Two sizes: memory flat in file size shows as equal peaks.
    for f in [frames.div_ceil(4).max(1), frames] {
        let p = dir.path().join(format!("bench{f}.vcd"));
        let opts = RunOptions::default();
        write_run(&p, &s, &mut ModelDut::new(&s), f, &opts, (0, u64::MAX)).unwrap();
        let mb = std::fs::metadata(&p).unwrap().len() as f64 / 1e6;
        let (tc, mc, cc) = run("check", &p);
        let (tw, mw, cw) = run("wellen", &p);
        println!(
            "eskin34 {f} frames, {mb:.1} MB VCD: check {:.0} MB/s ({mc:.0} MB peak, {cc:.2} CPU s), wellen multi-threaded load {:.0} MB/s ({mw:.0} MB peak, {cw:.2} CPU s); check / wellen = {:.2} (goal >= 1.0)",
            mb / tc,
            mb / tw,
            tw / tc
        );
        sizes.push((mb, mc));
    }
    println!(
        "check's peak memory: {:.0} MB at {:.0} MB of VCD, {:.0} MB at {:.0} MB",
        sizes[0].1, sizes[0].0, sizes[1].1, sizes[1].0
    );
}
