//! host: what a host does with the link's bytes when it knows the mix.
//!
//! - `samples`: [`Samples`], `link::Decoder` with each record named and
//!   timed from the schedule (`lut_gen::PacketInstants`): the decoder that
//!   `slotforge decode` and the Python package (`host/python`) share, so
//!   the two give the same `sampled_s` for the same byte stream;
//! - `sigrok`: the text of a sigrok protocol decoder for a mix's packets,
//!   stacked on sigrok's `uart` decoder (`slotforge sigrok`).

mod samples;
mod sigrok;

pub use samples::{Sample, Samples};
pub use sigrok::{sigrok_decoder, SigrokDecoder};
