//! slotforge's link to the host, without any simulator or HDL.
//!
//! - [`format`](mod@format): the packet format of `docs/packet-format.md` (sync marker,
//!   frame counter and slice, per-sample records, CRC-16/MODBUS): the one
//!   home of every byte's meaning;
//! - `uart`: the UART character (start, 8 data bits LSB first, parity,
//!   stop bits) and its divider from the clock;
//! - `tx`: the transmitter's cycle model (packetizer, FIFO, serializer,
//!   UART), which the judge uses to predict the line bit by bit and the
//!   audit to measure the backlog and the latency;
//! - `axis`: the AXI4-Stream form (byte beats, `tlast`, the slave's
//!   guarantee and the `tready` patterns back ends drive);
//! - `decode`: a streaming decoder of the bytes a host received, with
//!   counts of lost packets, CRC errors and resyncs;
//! - `rx`: a UART receiver that turns a sampled line back into bytes.
//!
//! No dependencies, so a host application can embed the decoder.

mod axis;
mod decode;
// A public namespace, not an export list: the packet format's constants and
// word builders (`format::SYNC`, `format::END`, `format::header`,
// `format::record`) read as what they are only with their module's name.
pub mod format;
mod rx;
mod tx;
mod uart;

pub use axis::{AxisFormat, ReadyDriver, ReadyPattern, Tlast};
pub use decode::{Decoded, Decoder, Packet, Stats};
pub use format::Token;
pub use rx::{RxByte, UartRx};
pub use tx::{steady_state, ByteOnLine, HeaderOnLine, Line, SteadyState, TxConfig, TxModel};
pub use uart::{Parity, UartFormat};

/// Private items that this crate's tests check directly (`tests/units/`):
/// the crate has no unit-test harness (`[lib] test = false`, one build of
/// it less in `make test`), so they are reached from the integration tests
/// here.  Not an API: no other crate uses it.
#[doc(hidden)]
pub mod for_tests {
    pub use crate::tx::header_state;
}
