//! Waveforms: VCD (lexed in parallel) and FST read from any simulator and
//! checked, windows locked onto their frame phase, and a run written out as
//! VCD, FST and a GTKWave save file.

mod fst;
mod lex;
mod lock;
mod read;
mod write;

pub use fst::from_vcd as fst_from_vcd;
// For this crate's tests only (`crate::for_tests`).
pub use lex::set_chunk_bytes;
pub use lock::{LockError, LockInfo, WindowCheck};
pub use read::{
    check_vcd, check_vcd_progress, check_vcd_with, parse_only as parse_vcd, read_cycles, CycleSink,
    VcdError, VcdInfo,
};
pub use write::{channels_path, edge_ps, id_code, wire_header, write_gtkw, write_run, VcdWriter};
