fn main() {
    let a: Vec<String> = std::env::args().collect();
    let g = formal::aiger::parse(&std::fs::read_to_string(&a[1]).unwrap()).unwrap();
    let f: u64 = a[2].parse().unwrap();
    let max: u64 = a.get(3).map_or(10 * f, |x| x.parse().unwrap());
    let t = std::time::Instant::now();
    let (r, st) = formal::symsim::run(&g, f, 2, max, None);
    let r = match r {
        formal::symsim::Found::Violated { step, .. } => format!("violated at {step}"),
        r => format!("{r:?}"),
    };
    println!(
        "{r} sat {} peak {} state {} {:.1} s",
        st.sat_calls,
        st.peak_nodes,
        st.state_nodes,
        t.elapsed().as_secs_f64()
    );
    let aim = std::fs::read_to_string(a[1].replace(".aag", ".aim")).unwrap_or_default();
    let names: std::collections::HashMap<usize, String> = aim
        .lines()
        .filter_map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            (f.len() == 4 && f[0] == "latch")
                .then(|| (f[1].parse().unwrap(), format!("{}[{}]", f[3], f[2])))
        })
        .collect();
    for j in st.kept {
        println!(
            "kept: latch {j} {}",
            names.get(&j).cloned().unwrap_or_default()
        );
    }
}
