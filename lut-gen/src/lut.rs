//! The slot LUT, in the two forms the gateware and the engineer need.
//!
//! The *frame table* has one entry per frame slot and branch.  The *compact*
//! form is the reference design's: a slice table (one row per slot of a
//! slice) whose cells are either the same channel in every slice, idle, or a
//! rotation group indexed by the slice counter (the 100 Hz channels sharing a
//! slot).  Both describe exactly the same schedule; [`CompactLut::expand`]
//! proves it.

use std::fmt::Write as _;

use serde::Serialize;

use crate::schedule::Schedule;

/// One cell of the slice table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum SliceCell {
    Idle,
    Fixed(u16),
    /// Index into [`CompactLut::rotations`].
    Rotate(u16),
}

#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct CompactLut {
    pub slots_per_slice: u64,
    pub slices_per_frame: u64,
    pub branches: usize,
    /// `[slot_in_slice][branch]`.
    pub slice_table: Vec<Vec<SliceCell>>,
    /// Each group has one entry per slice of the frame.
    pub rotations: Vec<Vec<Option<u16>>>,
}

impl CompactLut {
    pub fn from_schedule(s: &Schedule) -> CompactLut {
        let sps = s.grid.slots_per_slice;
        let k = s.grid.slices_per_frame;
        let nb = s.branches.len();
        let mut rotations: Vec<Vec<Option<u16>>> = Vec::new();
        let mut slice_table = Vec::with_capacity(sps as usize);
        for slot in 0..sps {
            let mut row = Vec::with_capacity(nb);
            for b in 0..nb {
                let column: Vec<Option<u16>> = (0..k)
                    .map(|j| s.at(j * sps + slot, b).map(|c| c as u16))
                    .collect();
                let cell = if column.iter().all(|c| *c == column[0]) {
                    match column[0] {
                        None => SliceCell::Idle,
                        Some(c) => SliceCell::Fixed(c),
                    }
                } else {
                    let g = rotations
                        .iter()
                        .position(|r| *r == column)
                        .unwrap_or_else(|| {
                            rotations.push(column.clone());
                            rotations.len() - 1
                        });
                    SliceCell::Rotate(g as u16)
                };
                row.push(cell);
            }
            slice_table.push(row);
        }
        CompactLut {
            slots_per_slice: sps,
            slices_per_frame: k,
            branches: nb,
            slice_table,
            rotations,
        }
    }

    /// The frame table this compact form stands for (`[slot][branch]`, row-major).
    pub fn expand(&self) -> Vec<Option<u16>> {
        let mut out = Vec::with_capacity(
            (self.slots_per_slice * self.slices_per_frame) as usize * self.branches,
        );
        for j in 0..self.slices_per_frame {
            for row in &self.slice_table {
                for cell in row {
                    out.push(match *cell {
                        SliceCell::Idle => None,
                        SliceCell::Fixed(c) => Some(c),
                        SliceCell::Rotate(g) => self.rotations[g as usize][j as usize],
                    });
                }
            }
        }
        out
    }

    /// LUT entries (cells plus rotation entries) of the compact form.
    pub fn entries(&self) -> usize {
        self.slice_table.len() * self.branches + self.rotations.iter().map(Vec::len).sum::<usize>()
    }
}

/// Bits of one branch field in a `slots.hex` word: a valid bit plus the channel index.
pub fn hex_field_bits(s: &Schedule) -> u32 {
    1 + s.channel_bits()
}

/// `slots.hex` for `$readmemh`: one word per frame slot; branch `b`'s field
/// `{valid, channel}` sits at bits `[b*F + F-1 : b*F]` with F = [`hex_field_bits`].
pub fn to_hex(s: &Schedule) -> String {
    let nb = s.branches.len();
    let f = hex_field_bits(s);
    let width = f as usize * nb;
    let digits = width.div_ceil(4);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "// slotforge slot LUT for mix `{}`: {} frame slots x {} branches",
        s.mix.name, s.grid.frame_slots, nb
    );
    let _ = writeln!(
        out,
        "// word = {{branch{}..branch0}}, each field {f} bits = {{valid, channel[{}:0]}}; address = slot in frame",
        nb - 1,
        f - 2
    );
    for (b, br) in s.branches.iter().enumerate() {
        let _ = writeln!(
            out,
            "// branch{b} = {} at bits [{}:{}]",
            br.name,
            (b + 1) * f as usize - 1,
            b * f as usize
        );
    }
    for slot in 0..s.grid.frame_slots {
        let mut word: u128 = 0;
        let mut bits = Vec::new();
        for b in 0..nb {
            let field: u128 = match s.at(slot, b) {
                Some(c) => (1u128 << (f - 1)) | c as u128,
                None => 0,
            };
            bits.push(field);
        }
        if width <= 128 {
            for (b, field) in bits.iter().enumerate() {
                word |= field << (b * f as usize);
            }
            let _ = writeln!(out, "{word:0digits$x}");
        } else {
            // Wide words: assemble hex digits from a bit vector.
            let mut v = vec![false; width];
            for (b, field) in bits.iter().enumerate() {
                for i in 0..f as usize {
                    v[b * f as usize + i] = field >> i & 1 == 1;
                }
            }
            let mut line = String::new();
            for d in (0..digits).rev() {
                let mut nib = 0;
                for i in 0..4 {
                    if v.get(d * 4 + i).copied().unwrap_or(false) {
                        nib |= 1 << i;
                    }
                }
                let _ = write!(line, "{nib:x}");
            }
            let _ = writeln!(out, "{line}");
        }
    }
    out
}

/// `slots.csv`: one row per frame slot, one column per branch (channel name or empty).
pub fn to_csv(s: &Schedule) -> String {
    let mut out = String::from("slot,slice,slot_in_slice,start_cycle");
    for b in &s.branches {
        out.push(',');
        out.push_str(&csv_field(&b.name));
    }
    out.push('\n');
    for slot in 0..s.grid.frame_slots {
        let _ = write!(
            out,
            "{slot},{},{},{}",
            slot / s.grid.slots_per_slice,
            slot % s.grid.slots_per_slice,
            slot * s.grid.slot_cycles
        );
        for b in 0..s.branches.len() {
            out.push(',');
            if let Some(c) = s.at(slot, b) {
                out.push_str(&csv_field(&s.mix.channels[c].name));
            }
        }
        out.push('\n');
    }
    out
}

fn csv_field(x: &str) -> String {
    if x.contains([',', '"', '\n']) {
        format!("\"{}\"", x.replace('"', "\"\""))
    } else {
        x.to_string()
    }
}

/// `slots.md`: the reference paper's Table 1 form, slot -> channel per branch,
/// with rotation groups spelled out by slice.
pub fn to_markdown(s: &Schedule) -> String {
    let lut = CompactLut::from_schedule(s);
    let g = &s.grid;
    let name = |c: u16| s.mix.channels[c as usize].name.as_str();
    let mut out = String::new();
    let _ = writeln!(out, "# Slot LUT: {}\n", s.mix.name);
    let _ = writeln!(
        out,
        "{} slots per {} us slice ({} cycles = {:.3} us each), {} slices per {} us frame, {} samples per frame.\n",
        g.slots_per_slice,
        s.mix.slice_us,
        g.slot_cycles,
        g.slot_cycles as f64 * 1e6 / g.clock_hz as f64,
        g.slices_per_frame,
        s.mix.frame_us,
        s.samples_per_frame()
    );
    let _ = writeln!(
        out,
        "Compact form: {} LUT entries (slice table + {} rotation group(s)) against {} for the full frame table.\n",
        lut.entries(),
        lut.rotations.len(),
        g.frame_slots as usize * s.branches.len()
    );
    out.push_str("| slot |");
    for b in &s.branches {
        let _ = write!(out, " {} |", b.name);
    }
    out.push_str("\n|---:|");
    for _ in &s.branches {
        out.push_str("---|");
    }
    out.push('\n');
    for (slot, row) in lut.slice_table.iter().enumerate() {
        let _ = write!(out, "| {slot} |");
        for cell in row {
            match cell {
                SliceCell::Idle => out.push_str(" - |"),
                SliceCell::Fixed(c) => {
                    let _ = write!(out, " {} |", name(*c));
                }
                SliceCell::Rotate(r) => {
                    let _ = write!(out, " R{r} |");
                }
            }
        }
        out.push('\n');
    }
    if !lut.rotations.is_empty() {
        out.push_str("\nRotation groups (entry used in each slice of the frame, chosen by the slice counter):\n\n| group |");
        for j in 0..g.slices_per_frame {
            let _ = write!(out, " slice {j} |");
        }
        out.push_str("\n|---|");
        for _ in 0..g.slices_per_frame {
            out.push_str("---|");
        }
        out.push('\n');
        for (r, group) in lut.rotations.iter().enumerate() {
            let _ = write!(out, "| R{r} |");
            for e in group {
                match e {
                    Some(c) => {
                        let _ = write!(out, " {} |", name(*c));
                    }
                    None => out.push_str(" - |"),
                }
            }
            out.push('\n');
        }
    }
    out
}
