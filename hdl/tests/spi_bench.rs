//! The SPI master and mux control of one branch in rust-hdl's simulator
//! (direct clock loop with `simulate()`) against a behavioural AD7940 with
//! the datasheet's delays in nanoseconds (the bench is `hdl`'s, behind the
//! `stock` feature): CS, SCLK, the mux pins and the captured code, cycle
//! by cycle.

use hdl::for_tests::{spi_trace as run, SPI_NS as NS, SPI_SLOT as SLOT};

fn check_spi(div: u64, setup: u64) {
    let r = setup + 16 * div;
    let word = 0x2d5b & 0x3fff;
    let t = run(div, setup, 4 * SLOT, word);
    assert!(t.converged, "simulate() converged in every cycle");
    // in reset: CS and SCLK idle high, the reset mux device enabled
    assert_eq!(t.reset.len(), 2);
    for &(cs_n, sclk, en) in &t.reset {
        assert!(cs_n && sclk);
        assert_eq!(en, 0b10);
    }
    for (k, &inst) in [0u64, 2 * SLOT].iter().enumerate() {
        // CS low exactly for R cycles from the instant
        assert!(inst == 0 || t.cs_n[inst as usize - 1]);
        for c in inst..inst + r {
            assert!(!t.cs_n[c as usize], "cs_n low in cycle {c}");
        }
        assert!(t.cs_n[(inst + r) as usize]);
        // SCLK: idle high, 16 falling edges, exact phase, CS-to-SCLK setup
        let falls: Vec<u64> = (inst + 1..inst + r + 1)
            .filter(|&c| t.sclk[c as usize - 1] && !t.sclk[c as usize])
            .collect();
        assert_eq!(falls.len(), 16);
        assert!(falls[0] - inst >= 1 && (falls[0] - inst) * NS >= 10, "t2");
        for (i, &f) in falls.iter().enumerate() {
            assert_eq!(f, inst + setup + i as u64 * div);
            for c in f..f + div / 2 {
                assert!(!t.sclk[c as usize]);
            }
            for c in f + div / 2..f + div {
                assert!(t.sclk[c as usize]);
            }
        }
        // the 14-bit code was captured despite worst-case delays
        let (done_at, ch, val) = t.done[k];
        assert_eq!(done_at, inst + r);
        assert_eq!(ch, [0, 7][k]);
        assert_eq!(val, word as u64);
    }
    // mux: reset value until instant 0, next channel from t+1, stable
    // through the next instant; one device at a time
    assert_eq!((t.sel[0], t.en[0]), (3, 0b10));
    for c in 1..2 * SLOT + 1 {
        assert_eq!(
            (t.sel[c as usize], t.en[c as usize]),
            (5, 0b01),
            "cycle {c}"
        );
    }
    for c in 2 * SLOT + 1..4 * SLOT {
        assert_eq!(
            (t.sel[c as usize], t.en[c as usize]),
            (3, 0b10),
            "cycle {c}"
        );
    }
    assert!(t.en.iter().all(|e| e.count_ones() == 1));
}

#[test]
fn spi_master_reads_ad7940_at_2_5_mhz() {
    check_spi(20, 1); // 50 MHz / 20 = 2.5 MHz, 200 ns low phase > t4
}

#[test]
fn spi_master_with_long_setup_and_slow_sclk() {
    // setup longer than half a period; R = 404 of the 500-cycle slot
    check_spi(24, 20);
}
