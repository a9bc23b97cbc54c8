//! The bricked caster stopped between the bricks of a tile: counted, on a
//! source that lights every brick and never ends a ray.

use super::*;
use crate::frame::Frame;
use crate::kernels::composite::EMPTY;
use crate::{RenderSettings, Volume};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Every brick of a grid, whole, its rays never terminating: counts
/// the bricks lit and the ray segments marched, and sets `stop` when
/// the `stop_at`-th brick is lit.
struct Counting<'a> {
    grid: BrickGrid,
    stop: &'a AtomicBool,
    stop_at: usize,
    lit: AtomicUsize,
    marched: AtomicUsize,
}

impl BrickSource for Counting<'_> {
    type Acc = FrontToBack;
    type Lit<'l>
        = ()
    where
        Self: 'l;
    type Scratch = ();

    fn cell_box(&self, n: usize) -> CellBox {
        let b = self.grid.coords(n);
        CellBox::new(&self.grid, b, self.grid.bounds(b))
    }

    fn light<'l>(&'l self, _: usize, _: &'l mut ()) {
        if self.lit.fetch_add(1, Ordering::Relaxed) + 1 == self.stop_at {
            self.stop.store(true, Ordering::Relaxed);
        }
    }

    fn march(&self, _: &mut FrontToBack, _: &(), _: usize, _: &Segment) -> bool {
        self.marched.fetch_add(1, Ordering::Relaxed);
        false
    }

    fn done(&self, _: usize) {}
}

/// (bricks lit, ray segments marched) for a 16² frame (one tile) of a
/// 64³ grid, stopped as the `stop_at`-th brick is lit.
fn cast_stopping_at(stop_at: usize) -> (usize, usize) {
    let volume = Volume::new([64; 3], vec![0.0; 64 * 64 * 64]).unwrap();
    let settings = RenderSettings {
        width: TILE,
        height: TILE,
        ..RenderSettings::default()
    };
    let frame = Frame::new(&settings, &volume).unwrap();
    let grid = BrickGrid::new(volume.dims());
    let bins = TileBins::of_boxes(
        grid.len(),
        |n| grid.coords(n),
        |n| grid.bounds(grid.coords(n)),
        &frame.sampling,
        &frame.view,
    );
    let stop = AtomicBool::new(false);
    let source = Counting {
        grid,
        stop: &stop,
        stop_at,
        lit: AtomicUsize::new(0),
        marched: AtomicUsize::new(0),
    };
    let mut pixels = vec![EMPTY; TILE * TILE];
    let progress = Progress::new(&|_| {});
    let progress = progress.stopping(&stop);
    render_source(
        &source,
        &bins,
        &frame.sampling,
        &frame.view,
        &mut pixels,
        Finish::Partial,
        &progress,
    );
    (source.lit.into_inner(), source.marched.into_inner())
}

#[test]
fn a_tile_stopped_while_its_rays_cross_a_brick_ends_with_that_brick() {
    // Never stopped: the tile's rays cross many bricks.
    let (all_lit, all_marched) = cast_stopping_at(usize::MAX);
    assert!(all_lit > 20, "{all_lit} bricks lit");
    // Stopped as its second brick is lit: the rays finish that brick
    // (at most one segment each) and cross no other.
    let (lit, marched) = cast_stopping_at(2);
    assert_eq!(lit, 2, "bricks lit after the stop");
    assert!(
        marched <= 2 * TILE * TILE && marched < all_marched / 10,
        "{marched} ray segments marched (of {all_marched} unstopped)"
    );
}
