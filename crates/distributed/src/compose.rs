//! Sort-last compositing of the ranks' partial images into the frame, on
//! rank 0: the fold, the binary-swap rounds ([`crate::schedule`]), then
//! the gather. Each message is the non-empty rectangle of the rows sent
//! ([`crate::wire`]).

use crate::kd::{Viewpoint, plane};
use crate::schedule::{Cut, Fold, Plan};
use crate::transport::{Transport, TransportError};
use crate::wire::{self, WireError};
use std::ops::Range;
use std::time::{Duration, Instant};
use thiserror::Error;
use volray_core::PartialImage;
use volray_core::sampling::grid::GridFrame;

/// Compositing failed: a rank was lost, or sent what is not a piece of
/// this frame.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ComposeError {
    #[error(transparent)]
    Transport(#[from] TransportError),
    #[error("from rank {rank}: {error}")]
    Wire { rank: usize, error: WireError },
}

/// What compositing cost this rank.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ComposeStats {
    /// The fold and the swap rounds.
    pub composite: Duration,
    /// Sending the parts to rank 0 and placing them.
    pub gather: Duration,
    /// Bytes this rank sent (fold, swaps and gather).
    pub bytes_sent: usize,
    /// Messages this rank sent.
    pub messages: usize,
    /// Swap rounds (plus one if this rank folded or was folded into).
    pub rounds: usize,
}

/// Whether this rank's image is in front of its partner's across `cut`.
fn mine_in_front(cut: &Cut, view: &Viewpoint, grid: &GridFrame) -> bool {
    view.low_in_front(cut.axis, plane(grid, cut.axis, cut.at)) == cut.mine_low
}

/// Composites `image`, this rank's partial image of the frame, with every
/// other rank's, by `plan` for the view from `view` (cuts placed by the
/// whole `grid`): the whole frame's partial image on rank 0, `None` on
/// the others.
pub fn composite<T: Transport + ?Sized>(
    transport: &T,
    plan: &Plan,
    view: &Viewpoint,
    grid: &GridFrame,
    mut image: PartialImage,
) -> Result<(Option<PartialImage>, ComposeStats), ComposeError> {
    let mut stats = ComposeStats::default();
    let start = Instant::now();
    let height = image.height();
    let send = |to: usize, bytes: &[u8], stats: &mut ComposeStats| {
        stats.bytes_sent += bytes.len();
        stats.messages += 1;
        transport.send(to, bytes)
    };
    let combine = |image: &mut PartialImage, from: usize, bytes: &[u8], front: bool| {
        wire::combine_into(image, bytes, front)
            .map(|_| ())
            .map_err(|error| ComposeError::Wire { rank: from, error })
    };
    match plan.fold {
        Some(Fold::Send { to }) => {
            stats.rounds = 1;
            send(to, &wire::encode(&image, 0..height), &mut stats)?;
            stats.composite = start.elapsed();
            return Ok((None, stats));
        }
        Some(Fold::Receive { from, cut }) => {
            stats.rounds = 1;
            let bytes = transport.receive(from)?;
            combine(&mut image, from, &bytes, mine_in_front(&cut, view, grid))?;
        }
        None => {}
    }
    // The rows this rank holds: halved each round.
    let mut rows: Range<usize> = 0..height;
    for swap in &plan.swaps {
        let mid = rows.start + rows.len() / 2;
        let (keep, give) = if swap.keep_first {
            (rows.start..mid, mid..rows.end)
        } else {
            (mid..rows.end, rows.start..mid)
        };
        let out = wire::encode(&image, give);
        stats.bytes_sent += out.len();
        stats.messages += 1;
        let bytes = transport.exchange(swap.partner, &out)?;
        combine(
            &mut image,
            swap.partner,
            &bytes,
            mine_in_front(&swap.cut, view, grid),
        )?;
        rows = keep;
        stats.rounds += 1;
    }
    stats.composite = start.elapsed();

    // The gather: every leader's rows to rank 0 (the leader of index 0).
    let start = Instant::now();
    let rank = transport.rank();
    if rank != 0 {
        send(0, &wire::encode(&image, rows), &mut stats)?;
        stats.gather = start.elapsed();
        return Ok((None, stats));
    }
    wire::clear(&mut image, 0..rows.start);
    wire::clear(&mut image, rows.end..height);
    for &leader in &plan.leaders[1..] {
        let bytes = transport.receive(leader)?;
        // Into empty pixels: the message's pixels as they are.
        combine(&mut image, leader, &bytes, true)?;
    }
    stats.gather = start.elapsed();
    Ok((Some(image), stats))
}
