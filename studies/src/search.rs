//! Setup shared by the search studies (`studies/examples/search_*.rs`).
