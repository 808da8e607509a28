//! The steps of `build` by the names `--only` and `--skip` take, and the
//! plan: every step with whether it runs, or why it is left out.

use super::{Args, Charts};

/// A step of `build`, in the order it runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    Audit,
    Lut,
    Verilog,
    Sim,
    Golden,
    Faults,
    Prove,
    Synth,
    Netlist,
    Timing,
    Figure7,
    Schedulability,
    Speed,
}

impl Step {
    pub const ALL: [Step; 13] = [
        Step::Audit,
        Step::Lut,
        Step::Verilog,
        Step::Sim,
        Step::Golden,
        Step::Faults,
        Step::Prove,
        Step::Synth,
        Step::Netlist,
        Step::Timing,
        Step::Figure7,
        Step::Schedulability,
        Step::Speed,
    ];

    /// Its name on the command line and the report's step id.
    pub fn name(self) -> &'static str {
        match self {
            Step::Audit => "audit",
            Step::Lut => "lut",
            Step::Verilog => "verilog",
            Step::Sim => "sim",
            Step::Golden => "golden",
            Step::Faults => "faults",
            Step::Prove => "prove",
            Step::Synth => "synth",
            Step::Netlist => "netlist",
            Step::Timing => "timing",
            Step::Figure7 => "figure7",
            Step::Schedulability => "schedulability",
            Step::Speed => "speed",
        }
    }

    /// Its title in the progress lines and the report.
    pub fn title(self) -> &'static str {
        match self {
            Step::Audit => "audit",
            Step::Lut => "slot LUT",
            Step::Verilog => "Verilog, ports.json, constraints",
            Step::Sim => "co-simulation",
            Step::Golden => "golden comparison",
            Step::Faults => "fault campaign",
            Step::Prove => "formal proof (all time)",
            Step::Synth => "synthesis estimate (yosys, nextpnr)",
            Step::Netlist => "netlist simulated (iCE40, a frame)",
            Step::Timing => "chart: timing of a slice",
            Step::Figure7 => "chart: Figure 7 for this mix's rates",
            Step::Schedulability => "chart: where scheduling breaks",
            Step::Speed => "chart: speed against accuracy",
        }
    }

    /// The charts about the mix, which `--charts none` leaves out.
    fn is_mix_chart(self) -> bool {
        matches!(
            self,
            Step::Timing | Step::Figure7 | Step::Schedulability | Step::Speed
        )
    }
}

impl std::str::FromStr for Step {
    type Err = ();

    /// A name of `--only` or `--skip` (spaces around it ignored).
    fn from_str(s: &str) -> Result<Step, ()> {
        let s = s.trim();
        Step::ALL.into_iter().find(|x| x.name() == s).ok_or(())
    }
}

/// Whether a step runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Run {
    Yes,
    Skip(SkipReason),
}

impl Run {
    pub fn runs(self) -> bool {
        !matches!(self, Run::Skip(_))
    }
}

/// Why a step is left out (not a failure: nobody asked for it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SkipReason {
    NotInOnly,
    Skipped,
    ChartsNone,
    /// The speed chart without the fault step it draws.
    FaultsLeftOut,
}

impl std::fmt::Display for SkipReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SkipReason::NotInOnly => "not in --only",
            SkipReason::Skipped => "--skip",
            SkipReason::ChartsNone => "--charts none",
            SkipReason::FaultsLeftOut => "draws this build's fault campaign, which is left out",
        })
    }
}

/// The steps named in `--only` or `--skip`, or why a name is unknown.
fn parse(flag: &str, names: &[String]) -> Result<Vec<Step>, String> {
    names
        .iter()
        .map(|n| {
            n.parse().map_err(|()| {
                let all: Vec<&str> = Step::ALL.iter().map(|s| s.name()).collect();
                format!(
                    "{flag}: there is no step `{n}`; the steps are {}",
                    all.join(", ")
                )
            })
        })
        .collect()
}

/// Whether `step` is named in `--only` (the fault campaign runs in full then).
pub fn only_names(a: &Args, step: Step) -> bool {
    a.only.iter().any(|n| n.parse() == Ok(step))
}

/// Which steps run: every step with whether it runs, or why a name given
/// is unknown (checked before anything runs).
pub fn plan(a: &Args) -> Result<Vec<(Step, Run)>, String> {
    let only = parse("--only", &a.only)?;
    let skip = parse("--skip", &a.skip)?;
    if only.contains(&Step::Speed) && !only.contains(&Step::Faults) {
        return Err(
            "--only speed: the chart draws this build's fault campaign; ask for both: --only faults,speed"
                .into(),
        );
    }
    let plan = Step::ALL
        .into_iter()
        .map(|step| {
            let run = if !only.is_empty() {
                if only.contains(&step) {
                    Run::Yes
                } else {
                    Run::Skip(SkipReason::NotInOnly)
                }
            } else if skip.contains(&step) {
                Run::Skip(SkipReason::Skipped)
            } else if step.is_mix_chart() && a.charts == Charts::None {
                Run::Skip(SkipReason::ChartsNone)
            } else {
                Run::Yes
            };
            (step, run)
        })
        .collect();
    Ok(speed_needs_faults(plan))
}

/// The speed chart draws this build's fault campaign: without the faults
/// step it is left out (said why), not skipped as if something failed.
fn speed_needs_faults(mut plan: Vec<(Step, Run)>) -> Vec<(Step, Run)> {
    let faults = plan.iter().any(|p| p.0 == Step::Faults && p.1.runs());
    for p in plan
        .iter_mut()
        .filter(|p| p.0 == Step::Speed && p.1.runs() && !faults)
    {
        p.1 = Run::Skip(SkipReason::FaultsLeftOut);
    }
    plan
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_step_is_found_by_its_name_and_no_other() {
        for step in Step::ALL {
            assert_eq!(format!(" {} ", step.name()).parse(), Ok(step));
        }
        assert_eq!("proof".parse::<Step>(), Err(()));
        assert_eq!(SkipReason::NotInOnly.to_string(), "not in --only");
        assert!(Run::Yes.runs() && !Run::Skip(SkipReason::Skipped).runs());
    }
}
