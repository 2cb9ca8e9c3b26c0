//! Who is who: the same person picked out in every camera, and followed
//! from frame to frame.
//!
//! In one frame each camera may hold several people (and people it made up).
//! A choice of one person (or none) per camera is *consistent* when the
//! keypoints triangulated from it reproject close to where each camera saw
//! them: the people of different persons' rays do not meet. The choice with
//! the most cameras whose mean reprojection error is below a threshold
//! (Pose2Sim's association threshold, 20 px) is the first person; its
//! detections are taken away and the search repeats for the next. Across
//! frames, each person found continues the track whose last position (the
//! mean of its keypoints) is nearest, within a distance that grows with the
//! time since it was last seen.

use glam::DVec3;

use crate::camera::Camera;
use crate::keypoints::{Person2d, ViewFrame};
use crate::triangulate::{reprojection_error, triangulate, Sighting};

/// Options of the association.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct AssociationOptions {
    /// Mean reprojection error (pixels) below which a choice of people is
    /// one person.
    pub max_error: f64,
    /// Keypoints scored below this are not used to associate.
    pub min_score: f32,
    /// Fewest keypoints triangulated for a choice to count.
    pub min_keypoints: usize,
    /// How far (metres) a person may move between two frames and keep
    /// their track (at 60 fps 0.5 m is a fast run's 30 m/s: generous on
    /// purpose, since frames can be missing).
    pub max_step: f64,
    /// The most people one camera's frame is searched for (its best-scored).
    pub max_candidates: usize,
}

impl Default for AssociationOptions {
    fn default() -> Self {
        AssociationOptions {
            max_error: 20.0,
            min_score: 0.3,
            min_keypoints: 5,
            max_step: 0.5,
            max_candidates: 4,
        }
    }
}

/// One person found in one frame: the index of their detection in each
/// camera's frame, and where they are.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Found {
    pub choice: Vec<Option<usize>>,
    pub centre: DVec3,
    pub error: f64,
}

fn mean_score(person: &Person2d) -> f32 {
    let n = person.keypoints.len().max(1) as f32;
    person.keypoints.iter().map(|k| k[2].max(0.0)).sum::<f32>() / n
}

/// The mean reprojection error and centre of the keypoints triangulated from
/// one choice of people, or `None` when too few keypoints are seen twice.
fn consistency(
    cameras: &[Camera],
    views: &[&ViewFrame],
    choice: &[Option<usize>],
    options: &AssociationOptions,
) -> Option<(f64, DVec3)> {
    let people: Vec<Option<&Person2d>> = choice
        .iter()
        .zip(views)
        .map(|(c, v)| c.and_then(|i| v.people.get(i)))
        .collect();
    let keypoints = people.iter().flatten().map(|p| p.keypoints.len()).max()?;
    let (mut error, mut sightings_used, mut centre, mut points) = (0.0, 0usize, DVec3::ZERO, 0);
    let mut sightings = Vec::with_capacity(cameras.len());
    for k in 0..keypoints {
        sightings.clear();
        for (c, person) in people.iter().enumerate() {
            let Some(&[x, y, s]) = person.and_then(|p| p.keypoints.get(k)) else {
                continue;
            };
            if s >= options.min_score && x.is_finite() && y.is_finite() {
                let pixel = glam::DVec2::new(x as f64, y as f64);
                sightings.push(Sighting::new(c, &cameras[c], pixel, s as f64));
            }
        }
        if sightings.len() < 2 {
            continue;
        }
        let Some(point) = triangulate(cameras, &sightings) else {
            continue;
        };
        for s in &sightings {
            error += reprojection_error(cameras, s, point).min(1e6);
            sightings_used += 1;
        }
        centre += point;
        points += 1;
    }
    (points >= options.min_keypoints)
        .then(|| (error / sightings_used as f64, centre / points as f64))
}

/// The people of one frame (see the module documentation), best first.
pub(crate) fn people_in_frame(
    cameras: &[Camera],
    views: &[&ViewFrame],
    max_people: usize,
    options: &AssociationOptions,
) -> Vec<Found> {
    // Each camera's candidates, best-scored first.
    let mut available: Vec<Vec<usize>> = views
        .iter()
        .map(|v| {
            let mut order: Vec<usize> = (0..v.people.len()).collect();
            order.sort_by(|&a, &b| mean_score(&v.people[b]).total_cmp(&mean_score(&v.people[a])));
            order.truncate(options.max_candidates);
            order
        })
        .collect();
    let mut found = Vec::new();
    while found.len() < max_people {
        let mut best: Option<(usize, f64, Vec<Option<usize>>, DVec3)> = None;
        let mut choice = vec![None; views.len()];
        // Every choice of one candidate or none per camera, odometer style.
        let mut digits = vec![0usize; views.len()];
        loop {
            for (c, d) in digits.iter().enumerate() {
                choice[c] = (*d > 0).then(|| available[c][*d - 1]);
            }
            let cameras_used = choice.iter().flatten().count();
            let better_possible = best
                .as_ref()
                .is_none_or(|(used, _, _, _)| cameras_used >= *used);
            if cameras_used >= 2 && better_possible {
                if let Some((error, centre)) = consistency(cameras, views, &choice, options) {
                    let better = error <= options.max_error
                        && best.as_ref().is_none_or(|(used, e, _, _)| {
                            cameras_used > *used || (cameras_used == *used && error < *e)
                        });
                    if better {
                        best = Some((cameras_used, error, choice.clone(), centre));
                    }
                }
            }
            // Next choice.
            let mut c = 0;
            while c < digits.len() {
                digits[c] += 1;
                if digits[c] <= available[c].len() {
                    break;
                }
                digits[c] = 0;
                c += 1;
            }
            if c == digits.len() {
                break;
            }
        }
        let Some((_, error, choice, centre)) = best else {
            break;
        };
        for (c, picked) in choice.iter().enumerate() {
            if let Some(i) = picked {
                available[c].retain(|j| j != i);
            }
        }
        found.push(Found {
            choice,
            centre,
            error,
        });
    }
    found
}

/// A person followed over the take: for each frame, their detection in each
/// camera (`None` for frames they were not found in).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Track {
    pub frames: Vec<Option<Vec<Option<usize>>>>,
    last: Option<(usize, DVec3)>,
}

impl Track {
    pub fn found_in(&self) -> usize {
        self.frames.iter().filter(|f| f.is_some()).count()
    }
}

/// Follows the people found in each frame over the take (see the module
/// documentation); tracks in the order of how many frames they hold, most
/// first.
pub(crate) fn follow(frames: Vec<Vec<Found>>, options: &AssociationOptions) -> Vec<Track> {
    let n = frames.len();
    let mut tracks: Vec<Track> = Vec::new();
    for (f, people) in frames.into_iter().enumerate() {
        let mut taken = vec![false; tracks.len()];
        for person in people {
            let nearest = tracks
                .iter()
                .enumerate()
                .filter(|(t, _)| !taken[*t])
                .filter_map(|(t, track)| {
                    let (at, centre) = track.last?;
                    let reach = options.max_step * (f - at) as f64;
                    let d = centre.distance(person.centre);
                    (d <= reach).then_some((t, d))
                })
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let t = match nearest {
                Some((t, _)) => t,
                None => {
                    tracks.push(Track {
                        frames: vec![None; n],
                        last: None,
                    });
                    taken.push(false);
                    tracks.len() - 1
                }
            };
            taken[t] = true;
            tracks[t].frames[f] = Some(person.choice);
            tracks[t].last = Some((f, person.centre));
        }
    }
    tracks.sort_by_key(|t| std::cmp::Reverse(t.found_in()));
    tracks
}
