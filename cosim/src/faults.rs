//! The fault campaign: every class of fault injected at many sites across
//! the frame (every branch; the first and last slot; frame and slice
//! boundaries; mid-frame), each run checked in full, plus clean runs over
//! random feasible mixes that must not be rejected (false alarms).
//!
//! Classes come at three levels: pin faults (`judge::faults::Fault`: a
//! wrong sample, a CS window late, an extra SCLK edge, a mux late or wrong,
//! two mux devices on), a reset glitch the design suffers while its `rst`
//! port stays low, and design-level faults built into the gateware itself
//! (`hdl::GatewareFault`: a slot-ROM word changed to another channel's, two
//! words swapped, the slot counter wrapping one early or late, the slice
//! counter off by one), which only the `rusthdl` target can carry.

use judge::faults::{Fault, FaultyDut};
use judge::run::{run_dut, Dut, ModelDut, RunOptions};
use judge::Report;
use lut_gen::Schedule;
use serde::Serialize;

use crate::error::SimError;
use crate::rusthdl::RustHdlDut;

/// The design the faults go into.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Target {
    /// The cycle-level reference model's pins (pin faults and reset glitches).
    Model,
    /// The gateware in rust-hdl's simulator (every class).
    Rusthdl,
}

/// A place in the frame where faults land.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Site {
    pub name: &'static str,
    /// Cycle of the run (from cycle 0) at or after which the fault lands.
    pub cycle: u64,
    /// The frame slot of that cycle.
    pub slot: u64,
}

/// One injection and what the checker made of it.
#[derive(Debug, Clone, Serialize)]
pub struct Injection {
    pub fault: String,
    pub site: &'static str,
    pub cycle: u64,
    pub detected: bool,
    pub divergences: u64,
    pub violations: u64,
    /// Invariant rules broken (first few).
    pub rules: Vec<String>,
}

/// A class of fault over all its sites.
#[derive(Debug, Clone, Serialize)]
pub struct ClassOutcome {
    pub name: String,
    /// `pins`, `reset` or `gateware`.
    pub level: &'static str,
    pub injected: u64,
    pub detected: u64,
    /// Injections the checker did not catch.
    pub missed: Vec<Injection>,
    /// Gateware faults whose outputs equalled the reference model's in every
    /// cycle of the run: equivalent on this mix (no output checker can see
    /// them; e.g. a frame one slot short when every slot converts the same
    /// channels), so not counted as injected.
    pub equivalent: Vec<Injection>,
}

/// Clean runs over random feasible mixes.
#[derive(Debug, Clone, Serialize)]
pub struct FalseAlarms {
    pub mixes: u64,
    pub runs: u64,
    /// Clean runs the checker wrongly rejected.
    pub rejected: u64,
    pub examples: Vec<String>,
}

/// The whole campaign.
#[derive(Debug, Clone, Serialize)]
pub struct Campaign {
    pub mix: String,
    pub target: Target,
    pub sites: Vec<Site>,
    pub classes: Vec<ClassOutcome>,
    pub injected: u64,
    pub detected: u64,
    pub false_alarms: FalseAlarms,
}

impl Campaign {
    /// Every injection caught and no clean run rejected.
    pub fn ok(&self) -> bool {
        self.detected == self.injected && self.false_alarms.rejected == 0
    }
}

/// The sites of a schedule: the start of frame 1 (a frame boundary, its
/// first slot), the start of slice 1 of frame 1 (a slice boundary), the
/// middle of frame 1 and the last slot of frame 1.
pub fn sites(s: &Schedule) -> Vec<Site> {
    let g = &s.grid;
    let f = g.frame_cycles;
    let slot = |c: u64| (c % f) / g.slot_cycles;
    let mut v = vec![Site {
        name: "frame-start",
        cycle: f,
        slot: 0,
    }];
    if g.slices_per_frame > 1 {
        let c = f + g.slots_per_slice * g.slot_cycles;
        v.push(Site {
            name: "slice-boundary",
            cycle: c,
            slot: slot(c),
        });
    }
    let mid = f + f / 2 + 7;
    v.push(Site {
        name: "mid-frame",
        cycle: mid,
        slot: slot(mid),
    });
    let last = f + (g.frame_slots - 1) * g.slot_cycles;
    v.push(Site {
        name: "last-slot",
        cycle: last,
        slot: g.frame_slots - 1,
    });
    v
}

fn outcome(fault: String, site: &Site, r: &Report) -> Injection {
    let mut rules: Vec<String> = Vec::new();
    for v in &r.violations {
        if rules.len() < 4 && !rules.contains(&v.rule) {
            rules.push(v.rule.clone());
        }
    }
    Injection {
        fault,
        site: site.name,
        cycle: site.cycle,
        detected: !r.ok,
        divergences: r.divergence_count,
        violations: r.violation_count,
        rules,
    }
}

/// One design-level fault at one site.
#[derive(Debug, Clone, Copy)]
struct DesignCase {
    fault: hdl::GatewareFault,
    site: Site,
    class: &'static str,
}

/// The ROM faults of branch `b` at `site`: the branch's first conversion
/// slot at or after the site's slot (cyclically) gets the word of the next
/// slot converting another channel, or is swapped with it.
fn rom_cases(s: &Schedule, b: usize, site: Site) -> Vec<DesignCase> {
    let n = s.grid.frame_slots;
    let conv: Vec<(u64, usize)> = (0..n).filter_map(|u| s.at(u, b).map(|c| (u, c))).collect();
    let Some(i) = conv
        .iter()
        .position(|&(u, _)| u >= site.slot)
        .or(if conv.is_empty() { None } else { Some(0) })
    else {
        return vec![];
    };
    let (u, ch) = conv[i];
    let Some(&(other, _)) = (1..conv.len())
        .map(|k| &conv[(i + k) % conv.len()])
        .find(|&&(_, c)| c != ch)
    else {
        return vec![];
    };
    vec![
        DesignCase {
            fault: hdl::GatewareFault::RomWord {
                branch: b,
                slot: u,
                from: other,
            },
            site,
            class: "rom-word",
        },
        DesignCase {
            fault: hdl::GatewareFault::RomSwap {
                branch: b,
                a: u,
                b: other,
            },
            site,
            class: "rom-swap",
        },
    ]
}

/// One design-level fault of each class, at the middle of frame 0 on the
/// first branch that has two channels (ROM faults), for a quick measure of
/// what a method can see.
pub fn one_gateware_fault_per_class(s: &Schedule) -> Vec<(&'static str, hdl::GatewareFault)> {
    let f = s.grid.frame_cycles;
    let mid = f / 2 + 7;
    let site = Site {
        name: "mid-frame",
        cycle: mid,
        slot: (mid % f) / s.grid.slot_cycles,
    };
    let mut v: Vec<(&'static str, hdl::GatewareFault)> = (0..s.branches.len())
        .map(|b| rom_cases(s, b, site))
        .find(|c| !c.is_empty())
        .unwrap_or_default()
        .into_iter()
        .map(|c| (c.class, c.fault))
        .collect();
    v.push((
        "slot-wrap-early",
        hdl::GatewareFault::SlotWrap { delta: -1 },
    ));
    v.push(("slot-wrap-late", hdl::GatewareFault::SlotWrap { delta: 1 }));
    if s.grid.slices_per_frame > 1 {
        v.push((
            "slice-count-short",
            hdl::GatewareFault::SliceWrap { delta: -1 },
        ));
        v.push((
            "slice-count-long",
            hdl::GatewareFault::SliceWrap { delta: 1 },
        ));
    }
    v
}

/// `hdl::RtlSim` with a design-level fault built in, as a [`Dut`].
pub fn gateware_dut(s: &Schedule, f: hdl::GatewareFault) -> Result<Box<dyn Dut>, SimError> {
    hdl::RtlSim::with_fault(s, f)
        .map(|sim| Box::new(GatewareDut(sim)) as Box<dyn Dut>)
        .map_err(|e| SimError::Hdl(e.to_string()))
}

/// Runs `jobs` on up to two threads (the machine's cores), in order.
fn parallel<T: Send, R: Send>(jobs: Vec<T>, f: impl Fn(T) -> R + Sync) -> Vec<R> {
    let n = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .clamp(1, 4);
    let mut slots: Vec<Option<R>> = (0..jobs.len()).map(|_| None).collect();
    let queue = std::sync::Mutex::new(jobs.into_iter().enumerate().collect::<Vec<_>>());
    let results = std::sync::Mutex::new(&mut slots);
    std::thread::scope(|sc| {
        for _ in 0..n {
            sc.spawn(|| loop {
                let job = queue.lock().expect("queue").pop();
                let Some((i, j)) = job else { break };
                let r = f(j);
                results.lock().expect("results")[i] = Some(r);
            });
        }
    });
    slots
        .into_iter()
        .map(|r| r.expect("every job ran"))
        .collect()
}

/// The campaign on `s` with `frames` frames per run (at least 3: faults land
/// in frame 1, and the next frame shows what a fault left behind), and
/// `false_alarm_mixes` random feasible mixes run clean.
pub fn campaign(
    s: &Schedule,
    target: Target,
    frames: u64,
    false_alarm_mixes: u64,
) -> Result<Campaign, SimError> {
    let frames = frames.max(3);
    if target == Target::Rusthdl {
        RustHdlDut::new(s)?;
    }
    let sites = sites(s);
    let opts = RunOptions::default();
    let make = || -> Box<dyn Dut> {
        match target {
            Target::Model => Box::new(ModelDut::new(s)),
            Target::Rusthdl => Box::new(RustHdlDut::new(s).expect("built once already")),
        }
    };
    // pin faults and reset glitches at every site
    let mut pin_jobs = Vec::new();
    for site in &sites {
        for f in Fault::all(s) {
            pin_jobs.push((f, *site));
        }
    }
    let pin = parallel(pin_jobs, |(f, site)| {
        let mut dut = FaultyDut::new(s, make(), f, site.cycle);
        let r = run_dut(s, &mut dut, frames, &opts, "faults", None);
        let level = if f == Fault::ResetGlitch {
            "reset"
        } else {
            "pins"
        };
        // a fault that found nothing to change is not counted as injected
        dut.injected()
            .then(|| (f.class(), level, outcome(f.name(), &site, &r)))
    });
    // design-level faults in the gateware
    let mut design = Vec::new();
    if target == Target::Rusthdl {
        for site in &sites {
            for b in 0..s.branches.len() {
                design.extend(rom_cases(s, b, *site));
            }
        }
        for (delta, class) in [(-1, "slot-wrap-early"), (1, "slot-wrap-late")] {
            design.push(DesignCase {
                fault: hdl::GatewareFault::SlotWrap { delta },
                site: sites[0],
                class,
            });
        }
        if s.grid.slices_per_frame > 1 {
            for (delta, class) in [(-1, "slice-count-short"), (1, "slice-count-long")] {
                design.push(DesignCase {
                    fault: hdl::GatewareFault::SliceWrap { delta },
                    site: sites[0],
                    class,
                });
            }
        }
    }
    let design = parallel(design, |c| {
        let name = format!("{}: {:?}", c.class, c.fault);
        match hdl::RtlSim::with_fault(s, c.fault) {
            Ok(sim) => {
                let mut dut = GatewareDut(sim);
                let r = run_dut(s, &mut dut, frames, &opts, "faults", None);
                let equivalent = r.ok && r.model_compared && r.divergence_count == 0;
                Some((c.class, "gateware", outcome(name, &c.site, &r), equivalent))
            }
            // a fault the mix's gateware cannot hold (e.g. a frame too long for the full LUT)
            Err(_) => None,
        }
    });
    let mut classes: Vec<ClassOutcome> = Vec::new();
    for (class, level, inj, equivalent) in pin
        .into_iter()
        .flatten()
        .map(|(c, l, i)| (c, l, i, false))
        .chain(design.into_iter().flatten())
    {
        let c = match classes.iter_mut().find(|c| c.name == class) {
            Some(c) => c,
            None => {
                classes.push(ClassOutcome {
                    name: class.to_string(),
                    level,
                    injected: 0,
                    detected: 0,
                    missed: vec![],
                    equivalent: vec![],
                });
                classes.last_mut().expect("just pushed")
            }
        };
        if equivalent {
            c.equivalent.push(inj);
            continue;
        }
        c.injected += 1;
        if inj.detected {
            c.detected += 1;
        } else {
            c.missed.push(inj);
        }
    }
    let injected = classes.iter().map(|c| c.injected).sum();
    let detected = classes.iter().map(|c| c.detected).sum();
    Ok(Campaign {
        mix: s.mix.name.clone(),
        target,
        sites,
        classes,
        injected,
        detected,
        false_alarms: false_alarms(target, false_alarm_mixes),
    })
}

/// `hdl::RtlSim` with a fault built in, as a [`Dut`].
struct GatewareDut(hdl::RtlSim);

impl Dut for GatewareDut {
    fn step(&mut self, rst: bool, miso: u64) -> lut_gen::ports::Pins {
        self.0.step(rst, miso)
    }
}

/// Clean runs of `target` over the first `n` feasible mixes of
/// [`random_mix`]; every rejection is a false alarm.
pub fn false_alarms(target: Target, n: u64) -> FalseAlarms {
    let mut fa = FalseAlarms {
        mixes: 0,
        runs: 0,
        rejected: 0,
        examples: vec![],
    };
    let mut seed = 0;
    while fa.mixes < n && seed < 50 * n.max(1) {
        seed += 1;
        let text = random_mix(seed);
        let Ok(mix) = lut_gen::parse(std::path::Path::new("random.toml"), &text) else {
            continue;
        };
        let Ok(s) = lut_gen::synthesize(&mix) else {
            continue;
        };
        if lut_gen::ports::Layout::fits(&s).is_err() {
            continue;
        }
        let dut: Box<dyn Dut> = match target {
            Target::Model => Box::new(ModelDut::new(&s)),
            Target::Rusthdl => match RustHdlDut::new(&s) {
                Ok(d) => Box::new(d),
                Err(_) => continue,
            },
        };
        fa.mixes += 1;
        let mut dut = dut;
        let r = run_dut(&s, &mut dut, 2, &RunOptions::default(), "clean", None);
        fa.runs += 1;
        if !r.ok {
            fa.rejected += 1;
            if fa.examples.len() < 3 {
                fa.examples.push(format!("seed {seed}: {}", r.summary()));
            }
        }
    }
    fa
}

/// A random mix (TOML text) of 1-3 AD7940 branches with 2 ms frames, 1-3
/// mux devices each, random SCLK and settling, and 2-9 channels at rates
/// from 500 Hz to 8 kHz; some are infeasible on purpose.
pub fn random_mix(seed: u64) -> String {
    crate::mixgen::random_mix(seed, &crate::mixgen::Shape::default())
}
