//! Channel names written short, as the mix's bulk patterns write them, for
//! the report's tables and the scenes `build` runs.

/// Names written short: runs of a prefix with consecutive numbers as the
/// mix's bulk patterns write them (`CH{1..25}`), the rest as they are.
pub fn short_names(names: &[&str]) -> String {
    let split = |n: &str| {
        let d = n.trim_end_matches(|c: char| c.is_ascii_digit());
        let digits = &n[d.len()..];
        let plain = !digits.is_empty() && (digits == "0" || !digits.starts_with('0'));
        plain
            .then(|| digits.parse::<u64>().ok().map(|k| (d.to_string(), k)))
            .flatten()
    };
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < names.len() {
        let mut j = i + 1;
        if let Some((p, k)) = split(names[i]) {
            while j < names.len() && split(names[j]) == Some((p.clone(), k + (j - i) as u64)) {
                j += 1;
            }
            if j - i > 2 {
                out.push(format!("{p}{{{k}..{}}}", k + (j - i - 1) as u64));
                i = j;
                continue;
            }
        }
        out.push(names[i].to_string());
        i += 1;
    }
    out.join(",")
}
