//! The command line the noise-level studies share: `DATA [TAKES] [SIGMAS] [MORE...]`.

use std::error::Error;
use std::path::PathBuf;

use mocap_clean::dataset::{list_bvh, load_takes, paths_in_split, Split, SplitFractions, Take};

/// Parsed study arguments.
pub struct StudyArgs {
    /// The folder of clean takes.
    pub data: PathBuf,
    /// At most this many validation takes (default 40).
    pub takes: usize,
    /// The noise levels, degrees (default 0,1,2,4,6,8,10).
    #[allow(dead_code)] // not every study has levels
    pub sigmas: Vec<f32>,
    /// Arguments after SIGMAS, for the study's own.
    #[allow(dead_code)] // not every study has more
    pub rest: Vec<String>,
}

pub fn parse() -> Result<StudyArgs, Box<dyn Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let data = PathBuf::from(args.first().ok_or("DATA folder needed")?);
    let takes: usize = args.get(1).map_or(Ok(40), |s| s.parse())?;
    let sigmas = args
        .get(2)
        .map_or("0,1,2,4,6,8,10", String::as_str)
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    Ok(StudyArgs {
        data,
        takes,
        sigmas,
        rest: args.iter().skip(3).cloned().collect(),
    })
}

impl StudyArgs {
    /// The first `takes` validation takes of `data` (the training code's
    /// split by take).
    #[allow(dead_code)] // not every study reads only validation takes
    pub fn validation_takes(&self) -> Result<Vec<Take>, Box<dyn Error>> {
        let paths = paths_in_split(
            &list_bvh(std::slice::from_ref(&self.data))?,
            Split::Validation,
            &SplitFractions::default(),
        );
        Ok(load_takes(&paths[..self.takes.min(paths.len())])?)
    }
}
