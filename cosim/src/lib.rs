//! cosim (under construction)
