//! Setup shared by the fuse studies (`studies/examples/fuse_*.rs`).
