use lut_gen::AuditReport;
use measure::for_tests::branch_caption;
use measure::{budget_tables, Tightest};

/// Text outside backticks has no `_` (no field name shown as a word).
fn plain_has_underscore(t: &str) -> bool {
    t.split('`').step_by(2).any(|p| p.contains('_'))
}

/// Every preset and a few random mixes: headers and row labels in
/// words, every table whole (each row as wide as its header), each
/// channel one row, and the tightest limit is the most used figure
/// of the branch table.
/// A number printed with more than three decimals: a float written
/// out as it is stored, not as a reader wants it.
fn raw_float(cell: &str) -> bool {
    let b = cell.as_bytes();
    (1..b.len()).any(|i| {
        b[i - 1] == b'.'
            && i >= 2
            && b[i - 2].is_ascii_digit()
            && b[i..].iter().take_while(|c| c.is_ascii_digit()).count() > 3
    })
}

#[test]
fn the_audit_tables_are_words_whole_and_once() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut mixes = Vec::new();
    for e in std::fs::read_dir(root.join("mixes")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            mixes.push(lut_gen::parse(&p, &std::fs::read_to_string(&p).unwrap()).unwrap());
        }
    }
    // a part whose throughput is not a whole number of samples/s; two
    // branches with every slot used (a tie for what binds)
    for f in [
        "hdl/tests/data/cnvmix.toml",
        "formal/tests/data/ch60-20ms.toml",
    ] {
        let p = root.join(f);
        mixes.push(lut_gen::parse(&p, &std::fs::read_to_string(&p).unwrap()).unwrap());
    }
    for seed in 1..6 {
        let text = campaign::random_mix(seed, &campaign::Shape::default());
        mixes.push(lut_gen::parse(std::path::Path::new("r.toml"), &text).unwrap());
    }
    for mix in &mixes {
        let s = lut_gen::synthesize(mix).unwrap();
        let r = AuditReport::of_schedule(&s);
        let tables = budget_tables(&r);
        for (cap, t) in &tables {
            assert!(!plain_has_underscore(cap), "{cap}");
            for h in &t.columns {
                assert!(!plain_has_underscore(h), "{}: {cap}: {h}", mix.name);
            }
            assert!(t.rows.iter().all(|row| row.len() == t.columns.len()));
            for cell in t.rows.iter().flatten() {
                assert!(
                    !raw_float(cell),
                    "{}: {cap}: an unrounded number: {cell}",
                    mix.name
                );
            }
            if t.columns.len() == 2 {
                // label and value: the labels are words
                for row in &t.rows {
                    assert!(!plain_has_underscore(&row[0]), "{}: {}", mix.name, row[0]);
                }
            }
        }
        let ch = &tables.iter().find(|t| t.0 == "Channels").unwrap().1;
        let names: Vec<&String> = ch.rows.iter().map(|r| &r[0]).collect();
        assert_eq!(names.len(), mix.channels.len(), "{}", mix.name);
        assert_eq!(tables.iter().filter(|t| t.0 == "Channels").count(), 1);
        assert_eq!(
            r.link.is_some(),
            tables.iter().any(|t| t.0.starts_with("Link budget"))
        );
        let tight = Tightest::of(&r).unwrap();
        let most = if r.modes.len() > 1 {
            // every mode's figures, the busiest named with its mode
            let m = (r.modes.iter())
                .flat_map(|m| {
                    let l = m.link.as_ref().map(|l| l.utilization);
                    m.branches
                        .iter()
                        .flat_map(|b| [b.utilization, b.adc_utilization])
                        .chain(l)
                })
                .fold(0.0, f64::max);
            assert!(
                tight.what.contains("in mode `"),
                "{}: {}",
                mix.name,
                tight.what
            );
            m
        } else {
            r.branches
                .iter()
                .flat_map(|b| [b.utilization, b.adc_utilization])
                .chain(r.link.iter().map(|l| l.utilization))
                .fold(0.0, f64::max)
        };
        assert_eq!(tight.used, most, "{}", mix.name);
        // without modes, a branch that binds is the one the branch
        // table's caption names
        let caption = branch_caption(&r);
        if let (false, Some(b)) = (r.modes.len() > 1, tight.what.strip_prefix("branch `")) {
            let name = &b[..b.find('`').unwrap()];
            assert!(
                caption.contains(&format!("`{name}` is the most used")),
                "{}: {} / {caption}",
                mix.name,
                tight.what
            );
        }
    }
}
