//! Setup shared by the clean studies (`studies/examples/clean_*.rs`).
