//! The FPGA parts slotforge synthesizes for, simulates as netlists and
//! writes constraints for: one part per open family, each with the board
//! people buy it on. The one place a family's tool names live, so `synth
//! --fpga`, `sim --netlist`, `prove --netlist` and the constraint writers
//! agree on them.

use std::fmt;

/// An FPGA part of an open family (the yosys + nextpnr flows).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Fpga {
    /// Lattice iCE40HX8K-CT256 (iCE40-HX8K Breakout Board).
    Ice40Hx8k,
    /// Lattice LFE5U-25F-CABGA256 (Colorlight i5; ULX3S has the CABGA381).
    Ecp5_25k,
    /// Gowin GW1NR-LV9QN88PC6/I5 (Sipeed Tang Nano 9K).
    Gw1n9,
}

/// The family of a part: what yosys' `synth_<family>` and the cell models
/// (`<family>/cells_sim.v` in yosys' share directory) are named for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Family {
    Ice40,
    Ecp5,
    Gowin,
}

impl Fpga {
    /// Every part, in the order tables list them.
    pub const ALL: [Fpga; 3] = [Fpga::Ice40Hx8k, Fpga::Ecp5_25k, Fpga::Gw1n9];

    /// The name on the command line and in reports (`--fpga ice40-hx8k`).
    pub fn name(self) -> &'static str {
        match self {
            Fpga::Ice40Hx8k => "ice40-hx8k",
            Fpga::Ecp5_25k => "ecp5-25k",
            Fpga::Gw1n9 => "gw1n-9",
        }
    }

    pub fn family(self) -> Family {
        match self {
            Fpga::Ice40Hx8k => Family::Ice40,
            Fpga::Ecp5_25k => Family::Ecp5,
            Fpga::Gw1n9 => Family::Gowin,
        }
    }

    /// A part's name, or its family's (`ice40`, `ecp5`, `gowin`, which
    /// stand for the one part of that family slotforge knows).
    pub fn parse(text: &str) -> Result<Fpga, String> {
        let t = text.trim().to_ascii_lowercase();
        Fpga::ALL
            .into_iter()
            .find(|f| f.name() == t || f.family().name() == t)
            .ok_or_else(|| {
                let names: Vec<String> = Fpga::ALL
                    .iter()
                    .map(|f| format!("{} ({})", f.name(), f.family().name()))
                    .collect();
                format!(
                    "unknown FPGA `{text}`: slotforge knows {}",
                    names.join(", ")
                )
            })
    }
}

impl Family {
    /// yosys' name for the family: `synth_<name>`, `<name>/cells_sim.v`.
    pub fn name(self) -> &'static str {
        match self {
            Family::Ice40 => "ice40",
            Family::Ecp5 => "ecp5",
            Family::Gowin => "gowin",
        }
    }
}

impl fmt::Display for Fpga {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl fmt::Display for Family {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_and_families_parse_to_the_same_part_and_others_are_refused() {
        for f in Fpga::ALL {
            assert_eq!(Fpga::parse(f.name()), Ok(f));
            assert_eq!(Fpga::parse(f.family().name()), Ok(f));
            assert_eq!(Fpga::parse(&f.name().to_uppercase()), Ok(f));
        }
        let e = Fpga::parse("xc7a35t").unwrap_err();
        assert!(e.contains("xc7a35t") && e.contains("ecp5-25k"), "{e}");
    }
}
