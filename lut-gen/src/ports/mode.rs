//! The mode ports of `slotforge_top` (docs/timing.md, "Mode switches"):
//! present only for a mix with modes, after the link's ports, so no mix
//! without modes gains a port. `mode_sel` (pin select only) names the
//! mode wanted, `mode` the mode in force, both binary over
//! `Modes::select_bits` bits.

use super::*;

/// A mode port.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModePort {
    pub name: &'static str,
    pub dir: Dir,
    /// The port's key under `"mode"` in `ports.json`.
    pub key: &'static str,
}

/// `mode_sel` (input, pin select) and `mode` (output), in port order.
pub const MODE_PORTS: [ModePort; 2] = [
    ModePort {
        name: "mode_sel",
        dir: Dir::In,
        key: "sel",
    },
    ModePort {
        name: "mode",
        dir: Dir::Out,
        key: "mode",
    },
];

impl Layout {
    /// The mode ports after the link's: none without modes, only `mode`
    /// for `select = "auto"`.
    pub fn mode_ports(&self) -> &'static [ModePort] {
        match (self.mode_bits, self.mode_pin) {
            (0, _) => &[],
            (_, true) => &MODE_PORTS,
            (_, false) => &MODE_PORTS[1..],
        }
    }

    /// Every mode port bit with its direction (`mode_sel[0]`, ...), in port
    /// order: the last rows of [`Layout::bits`], which a board's
    /// constraints place.
    pub fn mode_port_bits(&self) -> Vec<(String, Dir)> {
        self.mode_ports()
            .iter()
            .flat_map(|p| (0..self.mode_bits).map(move |i| (format!("{}[{i}]", p.name), p.dir)))
            .collect()
    }
}

/// `ports.json`'s `"mode"`: the select kind, the width, the ports by key
/// and the modes' names by number; `None` without modes.
pub(super) fn manifest_mode(s: &Schedule, l: &Layout) -> Option<serde_json::Value> {
    use serde_json::json;
    let m = s.mix.modes.as_ref()?;
    let mut o = serde_json::Map::new();
    o.insert("select".into(), json!(m.select.name()));
    o.insert("bits".into(), json!(l.mode_bits));
    for p in l.mode_ports() {
        o.insert(p.key.into(), json!(p.name));
    }
    o.insert("names".into(), json!(m.names));
    o.insert("timing".into(), json!("docs/timing.md, \"Mode switches\""));
    Some(serde_json::Value::Object(o))
}
