//! Setup shared by the style studies (`studies/examples/style_*.rs`).
