//! The memory bound ([`MemoryBound`]) against what rendering really
//! allocates: a counting allocator measures the peak bytes held while a
//! renderer is built and renders one frame of a dense volume (every brick
//! occupied: the worst case the bound assumes), on every path. The bound
//! must hold, and be tight: within 10 % of the measured peak.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use volray_core::glam::DVec3;
use volray_core::{
    Blend, Classification, DEFAULT_CACHE_BUDGET, MemoryBound, Method, NonFinite, RenderSettings,
    Renderer, SampleType, Volume,
};
use volray_core::{FrameRequest, Render};

/// The system allocator, counting the bytes held and their peak.
struct Counting;

static HELD: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is forwarded unchanged to `System`, which upholds
// `GlobalAlloc`'s contract for the same layouts and pointers; the counters
// are plain atomics and never touch the memory.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's layout is passed on as it is.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let held = HELD.fetch_add(layout.size(), Ordering::SeqCst) + layout.size();
            PEAK.fetch_max(held, Ordering::SeqCst);
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as for `alloc`.
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            let held = HELD.fetch_add(layout.size(), Ordering::SeqCst) + layout.size();
            PEAK.fetch_max(held, Ordering::SeqCst);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` was allocated by `System` with `layout` (above).
        unsafe { System.dealloc(ptr, layout) };
        HELD.fetch_sub(layout.size(), Ordering::SeqCst);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: `ptr` and `layout` are the caller's, from `System`.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            if new_size >= layout.size() {
                let grown = new_size - layout.size();
                let held = HELD.fetch_add(grown, Ordering::SeqCst) + grown;
                PEAK.fetch_max(held, Ordering::SeqCst);
            } else {
                HELD.fetch_sub(layout.size() - new_size, Ordering::SeqCst);
            }
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Tests that measure take turns: the counters are the process's.
static MEASURING: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// The peak bytes allocated beyond those held before, while `f` runs.
fn peak_during(f: impl FnOnce()) -> usize {
    let before = HELD.load(Ordering::SeqCst);
    PEAK.store(before, Ordering::SeqCst);
    f();
    PEAK.load(Ordering::SeqCst) - before
}

/// A smooth, nowhere-constant field on `n³` points: under a ramp from a
/// non-zero opacity every voxel is visible, so every brick is occupied.
fn dense(n: usize) -> Volume {
    let h = 1.0 / (n - 1) as f64;
    Volume::from_fn([n, n, n], DVec3::splat(h), DVec3::ZERO, |p| {
        (1.0 + 0.3 * (7.0 * p.x).sin() * (5.0 * p.y).cos() + 0.2 * p.z) as f32
    })
    .unwrap()
}

#[test]
fn the_bound_holds_within_ten_percent_on_every_path() {
    let _turn = MEASURING.lock().unwrap_or_else(|e| e.into_inner());
    let volume = dense(97);
    let base = RenderSettings {
        width: 200,
        height: 160,
        opacity_ramp: (0.05, 0.5),
        ..RenderSettings::default()
    };
    let cases = [
        (
            // The bound assumes every brick lit: a faint transfer function
            // lets every ray through to the back (an opaque one hides
            // bricks, which are then not lit).
            "fast, pre-classified",
            RenderSettings {
                opacity_ramp: (0.01, 0.03),
                ..base.clone()
            },
        ),
        (
            "fast, post-classified",
            RenderSettings {
                classification: Classification::Post,
                ..base.clone()
            },
        ),
        (
            "fast, pre-classified, with shadows and ambient occlusion",
            RenderSettings {
                opacity_ramp: (0.01, 0.03),
                shadows: true,
                ambient_occlusion: Some(8.0),
                ..base.clone()
            },
        ),
        (
            "fast, post-classified, with ambient occlusion",
            RenderSettings {
                classification: Classification::Post,
                ambient_occlusion: Some(8.0),
                ..base.clone()
            },
        ),
        (
            "fast, maximum",
            RenderSettings {
                blend: Blend::Maximum,
                width: 1200,
                height: 1000,
                ..base.clone()
            },
        ),
        (
            "reference, pre-classified",
            RenderSettings {
                method: Method::Reference,
                ..base.clone()
            },
        ),
        (
            "reference, post-classified",
            RenderSettings {
                method: Method::Reference,
                classification: Classification::Post,
                ..base.clone()
            },
        ),
        (
            "reference, post-classified, with shadows and ambient occlusion",
            RenderSettings {
                method: Method::Reference,
                classification: Classification::Post,
                shadows: true,
                ambient_occlusion: Some(2.0),
                ..base.clone()
            },
        ),
        (
            "reference, pre-classified, with ambient occlusion",
            RenderSettings {
                method: Method::Reference,
                ambient_occlusion: Some(2.0),
                ..base.clone()
            },
        ),
    ];
    // The thread pool's own allocations, once, before anything is counted.
    Renderer::new(&dense(9))
        .unwrap()
        .render(FrameRequest::new(&RenderSettings {
            width: 8,
            height: 8,
            ..RenderSettings::default()
        }))
        .unwrap()
        .image();
    for (what, settings) in cases {
        let measured = peak_during(|| {
            let renderer = Renderer::new(&volume).unwrap();
            let image = renderer
                .render(FrameRequest::new(&settings))
                .unwrap()
                .image();
            assert!(image.pixels().iter().any(|p| p[3] > 0.5), "{what}");
        });
        let bound =
            MemoryBound::for_volume(&volume, &settings, NonFinite::Refuse, DEFAULT_CACHE_BUDGET);
        // The volume was allocated before: the rest is what rendering took.
        let expected = (bound.total() - bound.volume) as f64;
        let ratio = expected / measured as f64;
        println!("{what}: measured {measured} bytes, bound {expected} ({ratio:.3})");
        assert!(
            (1.0..=1.1).contains(&ratio),
            "{what}: bound {expected} for {measured} measured"
        );
    }
}

#[test]
fn the_bound_counts_a_cleaned_copy_and_a_dense_brick_store() {
    let settings = RenderSettings::default();
    let bound = |sample, non_finite, budget| {
        MemoryBound::new([257; 3], DVec3::ONE, sample, &settings, non_finite, budget)
    };
    let plain = bound(SampleType::F32, NonFinite::Refuse, usize::MAX);
    let cleaned = bound(SampleType::F32, NonFinite::Transparent, usize::MAX);
    let voxels = 257u128.pow(3);
    assert_eq!(plain.volume, 4 * voxels);
    // The copy (4 bytes a voxel) and the mask (a bit a voxel), and a flag per brick.
    assert_eq!(
        cleaned.cleaned,
        4 * voxels + voxels.div_ceil(64) * 8 + 32u128.pow(3)
    );
    // Every brick occupied and lit: 24 bytes a slot, 9³ slots per 8³
    // voxels, about 34 bytes a voxel with the bookkeeping.
    let per_voxel = plain.path as f64 / voxels as f64;
    assert!((34.0..35.0).contains(&per_voxel), "{per_voxel}");
    // A budget bounds the slots: the rest is the bookkeeping, a few
    // hundred bytes a brick (a brick holds 512 voxels).
    let budgeted = bound(SampleType::F32, NonFinite::Refuse, 64 << 20);
    let rest = budgeted.path - (64 << 20);
    let per_brick = rest as f64 / 32f64.powi(3);
    println!("bookkeeping: {per_brick} bytes a brick");
    assert!((200.0..400.0).contains(&per_brick), "{per_brick}");
    // 16-bit samples take 2 bytes a voxel, and have no non-finite values.
    let u16 = bound(SampleType::U16, NonFinite::Transparent, usize::MAX);
    assert_eq!((u16.volume, u16.cleaned), (2 * voxels, 0));
}

#[test]
fn a_cache_budget_bounds_the_memory_and_changes_no_pixel() {
    // 97³ dense: 1728 occupied bricks, 30 MiB of classified and lit slots.
    // With 6 MiB a fifth of the bricks fit, with 2 MiB one in fifteen; with
    // none, every brick is classified and lit in passing. The same pixels
    // every time, and the bound holds within 10 % of what the caches fill.
    let _turn = MEASURING.lock().unwrap_or_else(|e| e.into_inner());
    let volume = dense(97);
    let views: Vec<RenderSettings> = [0.0, 25.0, 25.0]
        .into_iter()
        .map(|azimuth| RenderSettings {
            width: 200,
            height: 160,
            opacity_ramp: (0.05, 0.5),
            camera: volray_core::Camera {
                azimuth,
                ..Default::default()
            },
            ..RenderSettings::default()
        })
        .collect();
    let unbounded = Renderer::new(&volume).unwrap();
    let want: Vec<_> = views
        .iter()
        .map(|s| unbounded.render(FrameRequest::new(s)).unwrap().image())
        .collect();
    drop(unbounded);
    for budget in [6 << 20, 2 << 20, 0] {
        let measured = peak_during(|| {
            let renderer = Renderer::new(&volume).unwrap().with_cache_budget(budget);
            for (s, want) in views.iter().zip(&want) {
                assert!(
                    renderer.render(FrameRequest::new(s)).unwrap().image() == *want,
                    "budget {budget}"
                );
            }
        });
        let bound = MemoryBound::for_volume(&volume, &views[0], NonFinite::Refuse, budget);
        let expected = (bound.total() - bound.volume) as f64;
        let ratio = expected / measured as f64;
        println!("budget {budget}: measured {measured} bytes, bound {expected} ({ratio:.3})");
        // The caches fill the budget only as far as the frames need:
        // with 6 MiB, the 657 bricks a frame lights, classified, and the
        // lit ones in use (given back after their last tile) leave 0.6 MiB
        // of it. The bound counts it all.
        let unfilled = if budget == 6 << 20 { 1 << 20 } else { 0 } as f64;
        assert!(
            ratio >= 1.0 && expected - unfilled <= 1.1 * measured as f64,
            "budget {budget}: bound {expected} for {measured} measured"
        );
    }
}
