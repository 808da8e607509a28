//! Board files (`constraints/*.toml`): which package pin each port bit goes
//! to on a board, and the constraint file of the board's FPGA family that
//! says so (iCE40 PCF, ECP5 LPF, Gowin CST).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use lut_gen::{Constraints, Dir, Fpga, Layout, Schedule, PORTS};
use serde::Deserialize;

use crate::HdlError;

/// A board file: which package pin each port bit goes to (docs/ports.md,
/// "Board files").
///
/// ```toml
/// name = "..."
/// fpga = "ice40-hx8k"    # the part: ice40-hx8k, ecp5-25k or gw1n-9 (default ice40-hx8k)
/// device = "hx8k"        # as the vendor names it (for the reader)
/// package = "ct256"
/// io_type = "LVCMOS33"   # LPF/CST I/O standard (default LVCMOS33)
/// [io_types]             # by pin name: pins in a bank at another voltage
/// "B11" = "LVCMOS18"
/// [pins]                 # explicit bits, e.g. clk = "J3", "adc_cs_n[0]" = "B6"
/// clk = "J3"
/// [pool]                 # remaining bits take these pins, in port-table order
/// pins = ["A5", "A6"]
/// ```
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Board {
    pub name: String,
    #[serde(default)]
    pub description: String,
    #[serde(default = "ice40", deserialize_with = "fpga")]
    pub fpga: Fpga,
    pub device: String,
    pub package: String,
    #[serde(default = "lvcmos33")]
    pub io_type: String,
    #[serde(default)]
    pub io_types: BTreeMap<String, String>,
    #[serde(default)]
    pub pins: BTreeMap<String, String>,
    #[serde(default)]
    pub pool: Pool,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pool {
    #[serde(default)]
    pub pins: Vec<String>,
}

// board files written before there were other families are iCE40 boards
fn ice40() -> Fpga {
    Fpga::Ice40Hx8k
}

fn lvcmos33() -> String {
    "LVCMOS33".into()
}

fn fpga<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Fpga, D::Error> {
    let t = String::deserialize(d)?;
    Fpga::parse(&t).map_err(serde::de::Error::custom)
}

/// The board file slotforge ships for a part (`constraints/`), as text:
/// `synth --fpga` places on it.
pub fn stock_board(fpga: Fpga) -> &'static str {
    match fpga {
        Fpga::Ice40Hx8k => include_str!("../../constraints/ice40-hx8k-breakout.toml"),
        Fpga::Ecp5_25k => include_str!("../../constraints/ulx3s-25f.toml"),
        Fpga::Gw1n9 => include_str!("../../constraints/tang-nano-9k.toml"),
    }
}

impl Board {
    pub fn load(path: &Path) -> Result<Board, HdlError> {
        let err = |m: String| HdlError::Board {
            path: path.display().to_string(),
            message: m,
        };
        let text = std::fs::read_to_string(path).map_err(|e| err(lut_gen::io_words(&e)))?;
        toml::from_str(&text).map_err(|e| err(lut_gen::toml_words(&e.to_string(), "")))
    }

    /// The constraint file for this board's family: its name and text.
    pub(crate) fn constraints(
        &self,
        s: &Schedule,
        path: &Path,
    ) -> Result<(String, String), HdlError> {
        let placed = self.place(s, path)?;
        let format = self.fpga.family().constraints();
        let mut t = String::new();
        let (c, family) = match format {
            Constraints::Pcf => ("#", "iCE40"),
            Constraints::Lpf => ("#", "ECP5"),
            Constraints::Cst => ("//", "Gowin"),
        };
        let _ = writeln!(
            t,
            "{c} slotforge_top {family} pin constraints for mix \"{}\" on board \"{}\" ({} {})",
            s.mix.name, self.name, self.device, self.package
        );
        let mhz = s.grid.clock_hz as f64 / 1e6;
        for (name, pin, dir) in &placed {
            let io = self.io_types.get(pin).unwrap_or(&self.io_type);
            let d = dir.verilog();
            let _ = match format {
                Constraints::Pcf => writeln!(t, "set_io {name} {pin}    # {d}"),
                Constraints::Lpf => writeln!(
                    t,
                    "LOCATE COMP \"{name}\" SITE \"{pin}\";    # {d}\nIOBUF PORT \"{name}\" IO_TYPE={io};"
                ),
                Constraints::Cst => writeln!(
                    t,
                    "IO_LOC \"{name}\" {pin};    // {d}\nIO_PORT \"{name}\" IO_TYPE={io};"
                ),
            };
        }
        if format == Constraints::Lpf {
            let _ = writeln!(t, "FREQUENCY PORT \"clk\" {mhz} MHZ;");
        }
        Ok((format.file().to_string(), t))
    }

    /// Every port bit's pin: named in [pins], else the pool's next, as
    /// `(name as place and route calls it, pin, direction)`.
    fn place(&self, s: &Schedule, path: &Path) -> Result<Vec<(String, String, Dir)>, HdlError> {
        let bits = Layout::new(s).bits();
        let err = |m: String| HdlError::Board {
            path: path.display().to_string(),
            message: m,
        };
        for k in self.pins.keys() {
            if !bits.iter().any(|(n, _)| n == k) {
                // Pins for bits another mix has (e.g. adc_cs_n[7]) are fine; only
                // names that can never be a port bit are errors.
                let base = k.split('[').next().unwrap_or("");
                if !PORTS.iter().any(|p| p.name == base)
                    && !lut_gen::MODE_PORTS.iter().any(|p| p.name == base)
                {
                    return Err(err(format!("[pins] names `{k}`, which is not a port bit")));
                }
            }
        }
        let mut pool = self
            .pool
            .pins
            .iter()
            .filter(|x| !self.pins.values().any(|v| v == *x));
        let have = bits
            .iter()
            .filter(|(b, _)| self.pins.contains_key(b))
            .count()
            + pool.clone().count();
        if have < bits.len() {
            return Err(HdlError::Pins {
                path: path.display().to_string(),
                message: format!(
                "mix \"{}\" has {} port bits, but board \"{}\" ({}) offers {have} pins ([pins] and [pool]): \
                 a mix with fewer branches or mux devices, or a board with more pins, fits",
                s.mix.name,
                bits.len(),
                self.name,
                self.fpga.part_number()
                ),
            });
        }
        let mut used: Vec<&str> = vec![];
        let mut placed = vec![];
        for (bit, dir) in &bits {
            let pin = match self.pins.get(bit) {
                Some(x) => x.as_str(),
                None => pool.next().map(String::as_str).unwrap_or_default(),
            };
            if used.contains(&pin) {
                return Err(err(format!("pin {pin} is assigned twice")));
            }
            used.push(pin);
            placed.push((pnr_name(&bits, bit), pin.to_string(), *dir));
        }
        Ok(placed)
    }
}

/// `Board::constraints`, for this crate's tests (`crate::for_tests`): the
/// method stays off `Board`'s public face.
pub fn board_constraints(
    b: &Board,
    s: &Schedule,
    path: &Path,
) -> Result<(String, String), HdlError> {
    b.constraints(s, path)
}

/// The name place-and-route tools give a port bit: yosys and nextpnr call
/// the only bit of a 1-bit vector port by the port's name.
pub(crate) fn pnr_name(bits: &[(String, Dir)], bit: &str) -> String {
    if let Some(base) = bit.strip_suffix("[0]") {
        let wider = format!("{base}[1]");
        if !bits.iter().any(|(n, _)| *n == wider) {
            return base.to_string();
        }
    }
    bit.to_string()
}

/// The iCE40 PCF without a board: every port bit, pins to fill in.
pub(crate) fn pcf_template(s: &Schedule) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "# slotforge_top iCE40 pin constraints (template) for mix \"{}\"",
        s.mix.name
    );
    let _ = writeln!(
        t,
        "# No board file was given: replace every <pin> and uncomment, or emit with a board file."
    );
    let bits = Layout::new(s).bits();
    for (bit, dir) in &bits {
        let _ = writeln!(
            t,
            "# set_io {} <pin>    # {}",
            pnr_name(&bits, bit),
            dir.verilog()
        );
    }
    t
}
