//! hdl (under construction)
