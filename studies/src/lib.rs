//! Shared setup of the research studies (`studies/examples/`). Nothing here
//! is product API: the studies reach the product crates through their front
//! doors, and what each study taught is written in `docs/research/`.

pub mod clean;
pub mod feet;
pub mod frames;
pub mod style;
