//! A counterexample's free inputs, step by step, from ABC's AIGER witness
//! (`cex.aiw`, written by `bmc3`/`pdr`) and yosys's map of the AIG's inputs
//! (`design.aim`: `input <index> <bit> <name>`), for any input of the
//! harness by its name.

use std::path::Path;

use crate::ProveError;

/// The values of the harness input `name` (bits `0..width`) in each step of
/// the witness in `dir`.
pub fn input(dir: &Path, name: &str, width: u32) -> Result<Vec<u64>, ProveError> {
    let aim = std::fs::read_to_string(dir.join("design.aim"))
        .map_err(|e| ProveError::Tool(format!("design.aim: {e}")))?;
    let bits: Vec<(usize, u32)> = aim
        .lines()
        .filter_map(|line| {
            let f: Vec<&str> = line.split_whitespace().collect();
            if f.len() != 4 || f[0] != "input" || f[3] != name {
                return None;
            }
            let (idx, bit) = (f[1].parse().ok()?, f[2].parse().ok()?);
            (bit < width).then_some((idx, bit))
        })
        .collect();
    let cex = std::fs::read_to_string(dir.join("cex.aiw"))
        .map_err(|e| ProveError::Tool(format!("ABC wrote no witness: {e}")))?;
    Ok(steps(&cex, &bits))
}

/// Each step's value of the input whose bits sit at `(index, bit)` in the
/// witness's input vectors.
fn steps(cex: &str, bits: &[(usize, u32)]) -> Vec<u64> {
    let mut lines = cex.lines().map(str::trim).filter(|l| !l.is_empty());
    // "1", "b0", the initial latch values, then one input vector per step.
    for _ in 0..3 {
        lines.next();
    }
    lines
        .take_while(|l| *l != ".")
        .map(|l| {
            let b = l.as_bytes();
            bits.iter()
                .filter(|&&(idx, _)| b.get(idx) == Some(&b'1'))
                .fold(0u64, |m, &(_, bit)| m | 1 << bit)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_named_bits_of_each_step() {
        // inputs: 0 = adc_miso[0], 1 = tready_any, 2 = adc_miso[1]
        let cex = "1\nb0\n000\n101\n010\n111\n.\n";
        assert_eq!(steps(cex, &[(0, 0), (2, 1)]), [3, 0, 3]);
        assert_eq!(steps(cex, &[(1, 0)]), [0, 1, 1]);
    }
}
