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

#[cfg(test)]
mod tests {
    use super::*;

    fn schedule(name: &str) -> Schedule {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join(format!("../testkit/mixes/{name}.toml"));
        crate::synthesize(&crate::load(&p).unwrap()).unwrap()
    }

    fn doc(s: &Schedule) -> serde_json::Value {
        serde_json::from_str(&manifest(s)).unwrap()
    }

    #[test]
    fn pin_select_has_mode_sel_and_mode_as_wide_as_the_modes_need() {
        let s = schedule("modes-pin");
        let l = Layout::new(&s);
        assert_eq!(l.mode_bits, 1);
        let names: Vec<&str> = l.mode_ports().iter().map(|p| p.name).collect();
        assert_eq!(names, ["mode_sel", "mode"]);
        let d = doc(&s);
        assert_eq!(d["mode"]["select"], "pin");
        assert_eq!(d["mode"]["sel"], "mode_sel");
        assert_eq!(d["mode"]["mode"], "mode");
        assert_eq!(d["mode"]["bits"], 1);
        assert_eq!(d["mode"]["names"], serde_json::json!(["fast", "slow"]));
        let ports = d["ports"].as_array().unwrap();
        let last: Vec<_> = ports[ports.len() - 2..]
            .iter()
            .map(|p| (p["name"].clone(), p["dir"].clone(), p["width"].clone()))
            .collect();
        assert_eq!(last[0], ("mode_sel".into(), "in".into(), 1.into()));
        assert_eq!(last[1], ("mode".into(), "out".into(), 1.into()));
        assert_eq!(
            l.mode_port_bits(),
            [
                ("mode_sel[0]".to_string(), Dir::In),
                ("mode[0]".to_string(), Dir::Out)
            ]
        );
        // a board places them: they end the port bits
        assert!(l.bits().ends_with(&l.mode_port_bits()));
    }

    #[test]
    fn auto_select_has_only_mode_and_three_modes_take_two_bits() {
        let s = schedule("modes-auto");
        let l = Layout::new(&s);
        assert_eq!((l.mode_bits, l.mode_ports().len()), (2, 1));
        let d = doc(&s);
        assert_eq!(d["mode"]["select"], "auto");
        assert!(d["mode"].get("sel").is_none());
        assert_eq!(d["ports"].as_array().unwrap().last().unwrap()["width"], 2);
    }

    #[test]
    fn a_mix_without_modes_keeps_its_ports() {
        for name in ["tiny", "mutants", "every_slot", "cnvmix2ms"] {
            let s = schedule(name);
            let l = Layout::new(&s);
            assert!(
                l.mode_ports().is_empty() && l.mode_port_bits().is_empty(),
                "{name}"
            );
            assert!(doc(&s).get("mode").is_none(), "{name}");
        }
    }
}
