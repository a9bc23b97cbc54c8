//! The time points a viewer serves (`volray view --frames`): a tab asked
//! for a time point other than the starting one reads it for itself and
//! holds it, its bytes reserved, until it is asked for another.

use super::FrameError;
use super::render::Context;
use crate::ledger::Reservation;
use volray_core::{Renderer, Volume};

/// Reads one time point of a file as a volume, or says why not in one line.
pub type ReadTimePoint = dyn Fn(usize) -> Result<Volume, String> + Send + Sync;

/// The time points a viewer serves (`volray view --frames`): `volume` is
/// the starting one; a tab asked for another reads it, holding it (its
/// bytes reserved) until it is asked for the next.
pub struct TimePoints {
    /// `[first, end)`, as the file counts its frames.
    pub range: [usize; 2],
    /// The time point `volume` is.
    pub start: usize,
    pub read: Box<ReadTimePoint>,
}

/// Makes `renderer` render the time point `asked` (`None`: the starting
/// one): a time point other than the starting one is read for this tab
/// and held, its bytes reserved, until another is asked for.
pub(super) fn at_time<'a>(
    points: &TimePoints,
    start: &'a Volume,
    asked: Option<usize>,
    renderer: &mut Renderer<'a>,
    held: &mut Option<(usize, Reservation)>,
    cx: &Context,
) -> Result<(), FrameError> {
    let asked = asked.unwrap_or(points.start);
    let [first, end] = points.range;
    if !(first..end).contains(&asked) {
        return Err(FrameError::Time(format!(
            "time point {asked} is not served: {first} to {}",
            end - 1
        )));
    }
    let now = held.as_ref().map_or(points.start, |(t, _)| *t);
    if now == asked {
        return Ok(());
    }
    // Back to the starting time point, letting go of the one held before
    // the next is read.
    let budget = renderer.cache_budget();
    let non_finite = cx.costs.non_finite();
    *renderer = Renderer::with_non_finite(start, non_finite)?.with_cache_budget(budget);
    *held = None;
    if asked == points.start {
        return Ok(());
    }
    let reserved = (cx.ledger).reserve(&format!("time point {asked}"), cx.costs.volume)?;
    let volume = (points.read)(asked).map_err(FrameError::Time)?;
    *renderer = Renderer::owning(volume, non_finite)?.with_cache_budget(budget);
    *held = Some((asked, reserved));
    Ok(())
}
