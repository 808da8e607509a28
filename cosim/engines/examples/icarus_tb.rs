//! Writes the icarus back end's testbench for a mix into a directory, to run it by hand:
//! `cargo run -p engines --example icarus_tb -- MIX DIR [CYCLES [STIMULUS]]`, then
//! `iverilog -g2005 -o sim.vvp tb.v slotforge_top.v && vvp -n sim.vvp` in DIR.
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let s = lut_gen::synthesize(&lut_gen::load(std::path::Path::new(&a[1])).unwrap()).unwrap();
    let d = std::path::Path::new(&a[2]);
    let cycles = a
        .get(3)
        .map(|c| c.parse().unwrap())
        .unwrap_or(s.grid.frame_cycles);
    let stimulus = a.get(4).map(|x| x.parse().unwrap()).unwrap_or_default();
    let tb = engines::icarus_testbench(&s, stimulus, judge::reset_cycles(&s, 4), cycles);
    std::fs::write(d.join("tb.v"), tb.tb).unwrap();
    for (name, text) in tb.tables {
        std::fs::write(d.join(name), text).unwrap();
    }
    std::fs::write(d.join("slotforge_top.v"), engines::verilog(&s).unwrap()).unwrap();
}
