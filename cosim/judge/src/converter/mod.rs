//! The converters as the judge sees them: the ADC models and their stimuli,
//! the command words on `adc_mosi` read back as the part reads them, and the
//! read of a part read with CNV low (AD7689) seen as a held read.

mod adc;
mod cnv_low;
mod command;

pub use adc::{Adc, Analog, Scene, Stimulus};
pub(crate) use cnv_low::LowRead;
pub(crate) use command::{CommandRead, Selected};
