//! Speed against accuracy of the verification methods.  The chart's input
//! is one small struct per method ([`MethodScore`]) that any measurement
//! can fill (today [`measure`] below; the fault campaign's detector matrix
//! later): the chart draws counts (n of N), a real-time line, and keeps
//! every point inside its axes.

use std::path::Path;
use std::time::Instant;

use cosim::{Backend, SimOptions};
use judge::faults::{Fault, FaultyDut};
use judge::run::{run_dut, Dut, ModelDut, RunOptions};
use judge::vcdout::VcdWriter;
use lut_gen::Schedule;
use report::{draw, Axes, Figure, Marker, Section, Series, Table};

/// One method: how fast it simulated this mix, and how many of the faults
/// that can reach it it detected.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodScore {
    /// One meaning per name across the report (`slot model`, `cycle model`,
    /// `rusthdl`, `verilator`, `icarus`, `check`).
    pub method: String,
    pub simulated_seconds: f64,
    pub wall_seconds: f64,
    pub detected: u64,
    /// Faults injected that can reach this method.
    pub of: u64,
    /// How the faults reach it.
    pub how: String,
}

impl MethodScore {
    /// Simulated seconds per wall second.
    pub fn speed(&self) -> f64 {
        self.simulated_seconds / self.wall_seconds.max(1e-9)
    }
}

const MARKERS: [Marker; 4] = [
    Marker::Circle,
    Marker::Triangle,
    Marker::Square,
    Marker::Cross,
];

/// The chart and its table for `scores`.
pub fn chart(scores: &[MethodScore]) -> Figure {
    let mut table = Table::new(&[
        "method",
        "simulated_seconds",
        "wall_seconds",
        "simulated_seconds_per_wall_second",
        "faults_detected",
        "faults_reaching_it",
        "how faults reach it",
    ]);
    let mut series = Vec::new();
    for (i, m) in scores.iter().enumerate() {
        table.push(vec![
            m.method.clone(),
            format!("{:.6}", m.simulated_seconds),
            format!("{:.4}", m.wall_seconds),
            format!("{:.6}", m.speed()),
            m.detected.to_string(),
            m.of.to_string(),
            m.how.clone(),
        ]);
        let pct = if m.of == 0 {
            0.0
        } else {
            100.0 * m.detected as f64 / m.of as f64
        };
        let mut sr = Series::scatter(
            &format!("{}: {} of {}", m.method, m.detected, m.of),
            vec![(m.speed(), pct)],
        )
        .with_marker(MARKERS[i % MARKERS.len()]);
        sr.labels = vec![(
            m.speed(),
            pct,
            format!("{} ({} of {})", m.method, m.detected, m.of),
        )];
        series.push(sr);
    }
    let speeds = scores.iter().map(|m| m.speed()).chain([1.0]);
    let (lo, hi) = speeds.fold((f64::MAX, f64::MIN), |a, v| (a.0.min(v), a.1.max(v)));
    let mut axes = Axes::new(
        "Speed against accuracy of the verification methods",
        "simulated seconds per wall second (log)",
        "faults detected (% of those reaching the method; counts in the legend)",
    );
    axes.log_x = true;
    // a decade of room on each side, so markers and labels stay inside
    axes.x_range = Some((lo / 10.0, hi * 10.0));
    axes.y_range = Some((-10.0, 115.0));
    axes.vlines = vec![(1.0, "real time".into())];
    Figure {
        stem: "speed-accuracy".into(),
        title: "Speed against accuracy".into(),
        caption: "x: simulated seconds per wall second, measured in this run (right of the line: faster than real time); y: share of the injected faults each method rejected, with counts n of N".into(),
        svg: draw(&axes, &series, 900, 480),
        table,
    }
}

/// The pin faults of the quick measure: each class once.
fn pin_faults(s: &Schedule) -> Vec<Fault> {
    let mut seen: Vec<&str> = Vec::new();
    Fault::all(s)
        .into_iter()
        .filter(|f| {
            let new = !seen.contains(&f.class());
            seen.push(f.class());
            new
        })
        .collect()
}

fn caught(s: &Schedule, dut: Box<dyn Dut>, f: Fault) -> bool {
    let at = s.grid.frame_cycles / 2 + 7;
    let mut d = FaultyDut::new(s, dut, f, at);
    !run_dut(s, &mut d, 2, &RunOptions::default(), "faults", None).ok
}

fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t = Instant::now();
    let v = f();
    (v, t.elapsed().as_secs_f64())
}

/// Measures every method on this mix now: each simulates it (speed), and
/// each pin fault class is injected once mid-frame 0 through the method's
/// own path (accuracy); design faults go into the rust-hdl gateware, the
/// only method that can carry them.  `icarus` is measured when `iverilog`
/// is present.
pub fn measure(s: &Schedule, vcd: &Path) -> Result<Vec<MethodScore>, String> {
    let g = &s.grid;
    let f = g.frame_cycles;
    let secs = |cycles: u64| cycles as f64 / g.clock_hz as f64;
    let pins = pin_faults(s);
    let np = pins.len() as u64;
    let e = |e: cosim::SimError| e.to_string();
    let mut out = Vec::new();
    // the slot-level model: no pins, so no pin fault reaches it
    let n = (1.0 / secs(f)).ceil().max(10.0) as u64;
    let (_, w) = timed(|| judge::run::run_model(s, n, judge::Stimulus::Pattern, 10));
    out.push(MethodScore {
        method: "slot model".into(),
        simulated_seconds: secs(n * f),
        wall_seconds: w,
        detected: 0,
        of: 0,
        how: "no pins: answers rate questions over hours; no fault reaches it".into(),
    });
    // the cycle-level model's pins (run_observed; `run` would take the slot model)
    let (r, w) = timed(|| cosim::run_observed(s, Backend::Model, 2, &SimOptions::default(), None));
    r.map_err(e)?;
    let k = pins
        .iter()
        .filter(|&&p| caught(s, Box::new(ModelDut::new(s)), p))
        .count() as u64;
    out.push(MethodScore {
        method: "cycle model".into(),
        simulated_seconds: secs(2 * f),
        wall_seconds: w,
        detected: k,
        of: np,
        how: "pin and reset faults on the reference model's own pins".into(),
    });
    // rust-hdl: pin faults on its pins, design faults built into it
    let (r, w) = timed(|| cosim::run(s, Backend::RustHdl, 1, &SimOptions::default()));
    r.map_err(e)?;
    let mut k = 0;
    for &p in &pins {
        k += caught(
            s,
            Box::new(cosim::RustHdlDut::new(s).map_err(|e| e.to_string())?),
            p,
        ) as u64;
    }
    let gw = cosim::faults::one_gateware_fault_per_class(s);
    let mut of = np;
    for &(_, gf) in &gw {
        if let Ok(mut d) = cosim::faults::gateware_dut(s, gf) {
            of += 1;
            k += !run_dut(s, &mut d, 2, &RunOptions::default(), "faults", None).ok as u64;
        }
    }
    out.push(MethodScore {
        method: "rusthdl".into(),
        simulated_seconds: secs(f),
        wall_seconds: w,
        detected: k,
        of,
        how: "pin and reset faults on its pins; ROM and counter faults built into it".into(),
    });
    // verilator: pin faults on its pins
    if crate::synth::tool_present("verilator") {
        let _ = cosim::run(s, Backend::Verilator, 1, &SimOptions::default()).map_err(e)?; // build once
        let (r, w) = timed(|| cosim::run(s, Backend::Verilator, 3, &SimOptions::default()));
        r.map_err(e)?;
        let v = cosim::rusthdl::verilog(s).map_err(e)?;
        let mut k = 0;
        for &p in &pins {
            let (dut, _) = cosim::verilator::VerilatedDut::new(&v).map_err(|e| e.to_string())?;
            k += caught(s, Box::new(dut), p) as u64;
        }
        out.push(MethodScore {
            method: "verilator".into(),
            simulated_seconds: secs(3 * f),
            wall_seconds: w,
            detected: k,
            of: np,
            how: "pin and reset faults on the pins of its compiled Verilog".into(),
        });
    }
    // check: VCDs of faulty pins read back
    let tmp = std::env::temp_dir().join(format!("slotforge-speed-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).map_err(|e| e.to_string())?;
    let mut k = 0;
    for &p in &pins {
        let path = tmp.join("f.vcd");
        let reset = judge::run::reset_cycles(s, 4);
        let mut wr = VcdWriter::create(&path, s, 0, reset + 2 * f).map_err(|e| e.to_string())?;
        let mut d = FaultyDut::new(s, Box::new(ModelDut::new(s)) as Box<dyn Dut>, p, f / 2 + 7);
        let _ = run_dut(
            s,
            &mut d,
            2,
            &RunOptions::default(),
            "faults",
            Some(&mut wr),
        );
        wr.finish().map_err(|e| e.to_string())?;
        k += !judge::check_vcd(s, &path, None)
            .map_err(|e| e.to_string())?
            .ok as u64;
    }
    let _ = std::fs::remove_dir_all(&tmp);
    if vcd.exists() {
        let (r, w) = timed(|| judge::check_vcd(s, vcd, None));
        let r = r.map_err(|e| e.to_string())?;
        out.push(MethodScore {
            method: "check".into(),
            simulated_seconds: secs(r.cycles),
            wall_seconds: w,
            detected: k,
            of: np,
            how: "a VCD of faulty pins, read back".into(),
        });
    }
    if crate::synth::tool_present("iverilog") {
        let (r, w) = timed(|| cosim::run(s, Backend::Icarus, 1, &SimOptions::default()));
        r.map_err(e)?;
        out.push(MethodScore {
            method: "icarus".into(),
            simulated_seconds: secs(f),
            wall_seconds: w,
            detected: k,
            of: np,
            how: "its VCD goes through check, so it detects what check detects".into(),
        });
    }
    Ok(out)
}

/// The section for `scores`.
pub fn section(scores: &[MethodScore]) -> (Section, String) {
    let line = scores
        .iter()
        .map(|m| {
            format!(
                "{} {:.3}x real time, {} of {}",
                m.method,
                m.speed(),
                m.detected,
                m.of
            )
        })
        .collect::<Vec<_>>()
        .join("; ");
    (
        Section {
            title: "Speed against accuracy".into(),
            paragraphs: vec![
                "Each method simulated this mix in this run; its speed is simulated acquisition time per wall second. Accuracy counts the faults each method rejected out of those that can reach it, each pin fault class injected once in the middle of frame 0 (design faults go into the rust-hdl gateware only).".into(),
                "slot model: the slot-level model (no pins; for rates and headroom over hours). cycle model: the cycle-level reference model's pins (the fault campaign's `model` target). rusthdl, verilator, icarus: the gateware in each simulator. check: any simulator's VCD read by the checker.".into(),
                format!("{line}."),
            ],
            figures: vec![chart(scores)],
            ..Section::default()
        },
        line,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_chart_shows_counts_and_a_real_time_line() {
        let m = |n: &str, sim: f64, d: u64, of: u64| MethodScore {
            method: n.into(),
            simulated_seconds: sim,
            wall_seconds: 1.0,
            detected: d,
            of,
            how: String::new(),
        };
        let f = chart(&[m("a", 1e-4, 3, 7), m("b", 40.0, 0, 0)]);
        assert!(
            f.svg.contains("a (3 of 7)") && f.svg.contains("real time"),
            "{}",
            f.svg
        );
        assert_eq!(f.table.rows[0][4], "3");
        assert_eq!(f.table.rows[0][5], "7");
    }
}
