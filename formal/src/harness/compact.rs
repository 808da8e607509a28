//! The harness's compact slot tables, for frames beyond the full tables'
//! [`FULL_TABLE_MAX_SLOTS`] (a 1 Hz channel's one-second frame).
//!
//! The idea is `lut_gen::lut::CompactLut`'s (hdl/DESIGN.md): a row per slot
//! of the slice that is either the same in every slice of the frame or a
//! rotation group indexed by the slice.  It is applied here to the
//! harness's own rows, which carry the mux address of the *next* instant
//! besides the lead channel, so it is computed from the schedule's rows,
//! not read from `CompactLut` (and never from `hdl`).  Two shadow counters,
//! the slot in the slice (`sis`) and the slice in the frame (`slc`), run
//! beside the frame slot; every other part of the harness is the same in
//! both forms.

use std::collections::HashMap;
use std::fmt::Write;

use lut_gen::FrameGrid;
use lut_gen::Schedule;

use super::{most_common, width, HarnessError, Row, FULL_TABLE_MAX_SLOTS};

/// One slot of the slice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Cell {
    /// The same row in every slice.
    Fixed(Row),
    /// A rotation group: one row per slice of the frame.
    Rotate(usize),
}

/// A branch's rows in compact form.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Compact {
    cells: Vec<Cell>,
    groups: Vec<Vec<Row>>,
}

impl Compact {
    /// `rows` (one per frame slot, `slices` slices of `sps` slots).
    fn new(rows: &[Row], sps: usize, slices: usize) -> Compact {
        let mut groups = Vec::new();
        let mut index: HashMap<Vec<Row>, usize> = HashMap::new();
        let cells = (0..sps)
            .map(|i| {
                let column: Vec<Row> = (0..slices).map(|j| rows[j * sps + i]).collect();
                if column.iter().all(|r| *r == column[0]) {
                    Cell::Fixed(column[0])
                } else {
                    // Ids in order of first use: deterministic output.
                    let next = groups.len();
                    let g = *index.entry(column.clone()).or_insert(next);
                    if g == next {
                        groups.push(column);
                    }
                    Cell::Rotate(g)
                }
            })
            .collect();
        Compact { cells, groups }
    }

    /// The frame's rows this form stands for.
    #[cfg(test)]
    fn expand(&self, slices: usize) -> Vec<Row> {
        (0..slices)
            .flat_map(|j| {
                self.cells.iter().map(move |c| match *c {
                    Cell::Fixed(r) => r,
                    Cell::Rotate(g) => self.groups[g][j],
                })
            })
            .collect()
    }
}

/// The shadow slot in the slice and slice in the frame, stepped with `slot`.
pub(super) fn counters(v: &mut String, g: &FrameGrid) {
    let (ib, kb) = (width(g.slots_per_slice), width(g.slices_per_frame));
    let _ = writeln!(
        v,
        "  // Compact tables: slot in the slice, slice in the frame.\n  \
         reg [{}:0] sis = 0;\n  reg [{}:0] slc = 0;\n  \
         wire slice_end = slot_end && sis == {ib}'d{};\n  \
         always @(posedge clk) if (st == 2'd2 && slot_end) begin\n    \
         sis <= slice_end ? {ib}'d0 : sis + {ib}'d1;\n    \
         if (slice_end) slc <= frame_end ? {kb}'d0 : slc + {kb}'d1;\n  end",
        ib - 1,
        kb - 1,
        g.slots_per_slice - 1,
    );
}

/// Branch `b`'s table: the rotation groups (each a case on `slc`), then the
/// slice table (a case on `sis`) that sets `tab{b}`.  Held to the full
/// tables' size: at most [`FULL_TABLE_MAX_SLOTS`] case arms.
pub(super) fn table(
    s: &Schedule,
    b: usize,
    rows: &[Row],
    word: &dyn Fn(&Row) -> String,
    ew: u32,
) -> Result<String, HarnessError> {
    let g = &s.grid;
    let (sps, slices) = (g.slots_per_slice as usize, g.slices_per_frame as usize);
    let c = Compact::new(rows, sps, slices);
    let arms = sps + c.groups.len() * slices;
    if arms as u64 > FULL_TABLE_MAX_SLOTS {
        return Err(HarnessError(format!(
            "mix `{}`: branch {}'s slot table needs {arms} case arms even in compact form \
             ({sps} slots per slice, {} rotation groups of {slices} slices), beyond the formal \
             harness's {FULL_TABLE_MAX_SLOTS}",
            s.mix.name,
            s.branches[b].name,
            c.groups.len()
        )));
    }
    let (ib, kb) = (width(g.slots_per_slice), width(g.slices_per_frame));
    let mut v = String::new();
    for (n, group) in c.groups.iter().enumerate() {
        let texts: Vec<String> = group.iter().map(word).collect();
        let default = most_common(&texts);
        let _ = writeln!(
            v,
            "  reg [{}:0] rot{b}_{n};\n  always @* case (slc)",
            ew - 1
        );
        for (j, t) in texts.iter().enumerate() {
            if *t != default {
                let _ = writeln!(v, "    {kb}'d{j}: rot{b}_{n} = {t};");
            }
        }
        let _ = writeln!(v, "    default: rot{b}_{n} = {default};\n  endcase");
    }
    let cells: Vec<String> = c
        .cells
        .iter()
        .map(|cell| match cell {
            Cell::Fixed(r) => word(r),
            Cell::Rotate(n) => format!("rot{b}_{n}"),
        })
        .collect();
    let default = most_common(&cells);
    v.push_str("  always @* case (sis)\n");
    for (i, t) in cells.iter().enumerate() {
        if *t != default {
            let _ = writeln!(v, "    {ib}'d{i}: tab{b} = {t};");
        }
    }
    let _ = writeln!(v, "    default: tab{b} = {default};\n  endcase");
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(lead: Option<u32>, d: u8) -> Row {
        Row {
            lead,
            mux0: (d, 0),
            mux1: (d, 1),
        }
    }

    #[test]
    fn expands_to_the_frame_and_shares_equal_groups() {
        // 3 slices of 2 slots: slot 0 fixed, slot 1 rotates.
        let a = row(Some(0), 0);
        let rows = vec![a, row(Some(1), 1), a, row(None, 0), a, row(Some(2), 1)];
        let c = Compact::new(&rows, 2, 3);
        assert_eq!(c.cells, [Cell::Fixed(a), Cell::Rotate(0)]);
        assert_eq!(c.expand(3), rows);
        // 2 slices of 3 slots: slots 1 and 2 rotate alike (one group), slot 0
        // rotates otherwise (a second one).
        let (x, y) = (row(Some(1), 1), row(Some(2), 2));
        let rows = vec![a, x, x, x, y, y];
        let c = Compact::new(&rows, 3, 2);
        assert_eq!(c.cells, [Cell::Rotate(0), Cell::Rotate(1), Cell::Rotate(1)]);
        assert_eq!(c.groups.len(), 2);
        assert_eq!(c.expand(2), rows);
    }
}
