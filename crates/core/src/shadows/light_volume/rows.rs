//! The light volume's sweep, row by row (see the parent module for the
//! sweep and what it costs): the samples each voxel's shadow ray takes
//! ([`Sweep`], [`Tap`]), the ring of slices they read ([`Slice`]), what a
//! row's samples can meet ([`Reach`]), and the instructions the rows are
//! compiled for ([`Isa`]). A light volume is swept from these; they know
//! nothing of it.

/// A row's span of no voxels.
const NONE: (usize, usize) = (usize::MAX, 0);

/// Slices a voxel's shadow ray is marched through before it takes the
/// light found there: interpolating that light blurs it (by a variance of
/// `w(1 − w)` voxels² per interpolation, `w` the crossing's fraction of a
/// voxel), so each voxel marches `REACH` slices and the blur is that of
/// one interpolation every `REACH` slices.
const REACH: usize = 4;

/// A voxel whose shadow ray leaves the grid within this many slices is
/// marched to the grid's face, sample by sample as the reference: near a
/// face the light changes abruptly from voxel to voxel (the march counts
/// whole samples before the face) and interpolating it there was off by
/// 0.03 on blobs that touch the faces.
const EXIT: usize = 8;

/// The most samples a segment takes. A segment is longer than this many
/// steps only on a grid whose spacings differ many times over with a
/// small step (5 mm slices of 0.5 mm pixels at step 0.1 take 100 a
/// slice): there the samples spread evenly, each standing for several.
const MAX_SAMPLES: usize = 64;

/// `T` is stored in units of `1/UNIT`.
pub(super) const UNIT: f32 = u16::MAX as f32;

/// The instructions a sweep's rows are compiled for: AVX2 where the CPU
/// has it, else the target's baseline (SSE2 on x86-64). Both take the same
/// operations in the same order for each voxel: the same light.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Isa {
    /// Only ever true where the CPU has AVX2 (see [`Isa::best`]).
    avx2: bool,
}

impl Isa {
    /// The target's baseline.
    #[cfg(test)]
    pub(crate) fn baseline() -> Self {
        Isa { avx2: false }
    }

    /// The best this CPU has.
    pub(crate) fn best() -> Self {
        #[cfg(target_arch = "x86_64")]
        let avx2 = std::arch::is_x86_feature_detected!("avx2");
        #[cfg(not(target_arch = "x86_64"))]
        let avx2 = false;
        Isa { avx2 }
    }
}

/// One slice of the ring: its voxels' step-corrected opacities and light,
/// each a plane of rows `n[0]` long, `n[1]` of them, inside a border of
/// one voxel of zeros (voxel `(ib, ic)` at `(ic + 1)·(n[0] + 2) + ib + 1`,
/// so that a sample on the grid's last column or row reads its
/// neighbour past it, with weight 0, without a test); and per row the
/// span `lo..=hi` of its voxels that are not transparent (`material`),
/// and of those whose light is not 1 (`shade`) (`lo > hi`: none).
///
/// Outside its spans a row's opacities are 0 and its light is 1 exactly,
/// so a sample that meets neither is not taken: it would multiply by 1
/// (the light comes out the same to the bit). The peers' 50³ grids are 9 %
/// material; taking only those samples made their sweep 1.39 ms on one
/// thread, from 1.49 (shadow rays half a voxel apart). So that a row need
/// not ask each sample, the slice also counts its rows with material
/// (`material_rows[r]`: those before row `r`), and with shade ([`Reach`]).
pub(super) struct Slice {
    pub(super) alpha: Vec<f32>,
    pub(super) light: Vec<f32>,
    pub(super) material: Vec<(usize, usize)>,
    pub(super) shade: Vec<(usize, usize)>,
    pub(super) material_rows: Vec<u32>,
    pub(super) shade_rows: Vec<u32>,
}

impl Slice {
    pub(super) fn new([nb, nc]: [usize; 2]) -> Self {
        let pb = nb + 2;
        let mut light = vec![0.0; pb * (nc + 2)];
        for row in light[pb..].chunks_mut(pb).take(nc) {
            row[1..=nb].fill(1.0);
        }
        Slice {
            alpha: vec![0.0; pb * (nc + 2)],
            light,
            material: vec![NONE; nc],
            shade: vec![NONE; nc],
            material_rows: vec![0; nc + 1],
            shade_rows: vec![0; nc + 1],
        }
    }

    /// Reads a row of opacities `source` (`u16` units) into `row` (its
    /// place in a slice's bordered plane, with the border each side), and
    /// its material span into `span`; the opacities the row held (`span`'s
    /// last) cleared first.
    pub(super) fn read_row(source: &[u16], row: &mut [f32], span: &mut (usize, usize)) {
        if span.0 <= span.1 {
            row[span.0 + 1..=span.1 + 1].fill(0.0);
        }
        *span = NONE;
        if let Some(lo) = source.iter().position(|&q| q > 0) {
            let hi = source.iter().rposition(|&q| q > 0).unwrap_or(lo);
            for (alpha, &q) in row[lo + 1..=hi + 1].iter_mut().zip(&source[lo..=hi]) {
                *alpha = f32::from(q) * (1.0 / UNIT);
            }
            *span = (lo, hi);
        }
    }

    /// `counts[r]`: how many of the rows before `r` have a span in `spans`.
    pub(super) fn count_rows(spans: &[(usize, usize)], counts: &mut [u32]) {
        let mut rows = 0;
        for (count, span) in counts[1..].iter_mut().zip(spans) {
            rows += u32::from(span.0 <= span.1);
            *count = rows;
        }
    }
}

/// The slices back and the rows across them (from a voxel's row) that a
/// set of a row's samples reads: a row whose reach holds no material (or,
/// for the light at the last sample, no shade) takes none of them.
/// Three quarters of the rows of the peers' 50³ grids have no material;
/// asked once a row, their sweep took 1.02 ms on one thread, from 1.39
/// asking each sample.
#[derive(Debug, Clone, Copy)]
struct Reach {
    slices: (usize, usize),
    rows: (isize, isize),
}

impl Reach {
    /// The reach of the samples `taps`: each reads two slices and two
    /// rows.
    fn of<'t>(taps: impl IntoIterator<Item = &'t Tap>) -> Self {
        let none = Reach {
            slices: (usize::MAX, 0),
            rows: (isize::MAX, isize::MIN),
        };
        taps.into_iter().fold(none, |r, tap| Reach {
            slices: (r.slices.0.min(tap.slices), r.slices.1.max(tap.slices + 1)),
            rows: (r.rows.0.min(tap.c), r.rows.1.max(tap.c + 1)),
        })
    }

    /// Whether a row of this reach from row `ic` of slices `nc` rows deep,
    /// in a slice `back` holds, is one `rows` counts (see [`Slice`]).
    fn meets(
        &self,
        ic: usize,
        nc: usize,
        back: &[Option<&Slice>],
        rows: fn(&Slice) -> &[u32],
    ) -> bool {
        let lo = (ic as isize + self.rows.0).clamp(0, nc as isize) as usize;
        let hi = (ic as isize + self.rows.1 + 1).clamp(0, nc as isize) as usize;
        let slices = back.get(self.slices.0..=self.slices.1.min(back.len() - 1));
        lo < hi
            && (slices.into_iter().flatten().flatten())
                .any(|slice| rows(slice)[hi] > rows(slice)[lo])
    }
}

/// A slice of a group being lit: the `n`-th, its light and shade taken out
/// of the ring while they are written.
pub(super) struct Lit {
    pub(super) n: usize,
    pub(super) light: Vec<f32>,
    pub(super) shade: Vec<(usize, usize)>,
}

/// Widens `span` to hold `lo..=hi`.
fn widen(span: &mut (usize, usize), (lo, hi): (usize, usize)) {
    *span = (span.0.min(lo), span.1.max(hi));
}

/// A thread's buffers for a row: how many samples each voxel near the
/// faces takes, and the opacity on the face for those that share one.
#[derive(Default)]
pub(super) struct Scratch {
    taken: Vec<usize>,
    face_alpha: Vec<f32>,
}

/// A point on every voxel's shadow ray of a slice, at the same offset from
/// each: `slices + w` slices back (`w` in [0, 1)), and across the slice
/// `b + wb` and `c + wc` voxels from the voxel.
#[derive(Debug, Clone, Copy)]
struct Tap {
    slices: usize,
    w: f32,
    b: isize,
    wb: f32,
    c: isize,
    wc: f32,
}

impl Tap {
    /// The point `f` slices back along `d` (across the slice: `[d_b, d_c]`
    /// per slice).
    fn at(f: f64, d: [f64; 2]) -> Self {
        let split = |x: f64| {
            let floor = x.floor();
            (floor as isize, (x - floor) as f32)
        };
        let (slices, w) = split(f);
        let (b, wb) = split(f * d[0]);
        let (c, wc) = split(f * d[1]);
        Tap {
            slices: slices as usize,
            w,
            b,
            wb,
            c,
            wc,
        }
    }

    /// The bilinear interpolation at the point from voxel (`ib`, `ic`) of
    /// a bordered plane of rows `pb` long (see [`Slice`]), the point no
    /// more than a voxel past the grid (the border reads 0). The passes
    /// ([`Sweep::pass`]) compute the same expression.
    #[inline(always)]
    fn bilinear(&self, ib: usize, ic: usize, pb: usize, plane: &[f32]) -> f32 {
        let x = (ib as isize + self.b + 1) as usize;
        let y = (ic as isize + self.c + 1) as usize;
        let (wb, wc) = (self.wb, self.wc);
        let row = |y: usize| plane[y * pb + x] * (1.0 - wb) + plane[y * pb + x + 1] * wb;
        row(y) * (1.0 - wc) + row(y + 1) * wc
    }
}

/// What every slice's rays share: the slices' size (`n`: rows `n[0]`
/// long, `n[1]` of them), the light's direction across them (`d`, per
/// slice), the march's samples per slice, and where their samples fall
/// in the slices behind.
pub(super) struct Sweep {
    pub(super) n: [usize; 2],
    d: [f64; 2],
    per_slice: f64,
    /// Rays that leave the grid within this many slices are marched to
    /// its face (at least a segment's reach: the slices it reads exist).
    exit_slices: usize,
    /// Slices kept while later ones read them: a face point `exit_slices`
    /// back lies between slices `exit_slices − 1` and `exit_slices` back,
    /// and the slices being done (a `group`).
    pub(super) ring: usize,
    /// Slices done at once, in one parallel loop: a slice reads the light
    /// no nearer than its last sample's slices back, so those before it
    /// may be done with it. Against a loop a slice, at two threads
    /// (medians of eight alternated runs): the peers' 65³ cloud 1.11 ms
    /// from 1.28, their 257³ cloud 37.4 from 38.5, their 50³ orbital
    /// unchanged (0.71 and 0.69).
    pub(super) group: usize,
    /// The samples of the rays that leave the grid no sooner than
    /// `exit_slices` on (up to [`MAX_SAMPLES`], each standing for `weight`
    /// of the march's), the light taken at the last.
    inner: Vec<Tap>,
    weight: f32,
    /// The samples of the others, one step apart: each ray takes those
    /// before the face.
    band: Vec<Tap>,
    /// What `inner` reads, its last sample's light, and what `band` and
    /// the faces read.
    reach: [Reach; 3],
}

impl Sweep {
    pub(super) fn new(n: [usize; 2], d: [f64; 2], per_slice: f64) -> Self {
        let (reach, exit_slices) = Self::reaches(per_slice);
        let samples = (reach as f64 * per_slice + 1e-9).floor() as usize;
        let count = samples.min(MAX_SAMPLES);
        let spread = samples as f64 / count.max(1) as f64;
        let band = ((exit_slices + 1) as f64 * per_slice + 1e-9).floor() as usize;
        let inner: Vec<Tap> = (1..=count)
            .map(|m| Tap::at(m as f64 * spread / per_slice, d))
            .collect();
        let band: Vec<Tap> = (1..=band)
            .map(|m| Tap::at(m as f64 / per_slice, d))
            .collect();
        // A face point lies less than `exit_slices` back, and its row
        // changes monotonically with how far: the ends bound it.
        let faces = [Tap::at(0.0, d), Tap::at(exit_slices as f64, d)];
        let group = inner.last().map_or(1, |last| last.slices.max(1));
        debug_assert!(group <= reach, "the ring holds a group");
        Sweep {
            group,
            n,
            d,
            per_slice,
            exit_slices,
            ring: Self::ring_size(per_slice),
            reach: [
                Reach::of(&inner),
                Reach::of(inner.last()),
                Reach::of(band.iter().chain(&faces)),
            ],
            inner,
            weight: spread as f32,
            band,
        }
    }

    /// For `per_slice` of the march's samples a slice: the slices a
    /// segment reaches back (at least `REACH`, and far enough for its last
    /// sample to lie beyond the slice behind, where the light is known,
    /// whatever the step), and those within which rays are marched to the
    /// face.
    fn reaches(per_slice: f64) -> (usize, usize) {
        let reach = REACH.max((1.0 / per_slice).ceil() as usize + 1);
        (reach, EXIT.max(reach))
    }

    /// The ring's slices for `per_slice` of the march's samples a slice:
    /// those `exit_slices + 1` back from a group's first, and a group (no
    /// more than the reach).
    pub(super) fn ring_size(per_slice: f64) -> usize {
        let (reach, exit_slices) = Self::reaches(per_slice);
        exit_slices + 1 + reach
    }

    /// Slices from voxel `i` of `n` to where its ray leaves the grid
    /// across one axis, at `d` voxels a slice.
    fn exit(i: usize, n: usize, d: f64) -> f64 {
        if d > 0.0 {
            (n - 1 - i) as f64 / d
        } else if d < 0.0 {
            i as f64 / -d
        } else {
            f64::INFINITY
        }
    }

    /// The light reaching each voxel of row `ic` of the `n`-th slice from
    /// the light ([`Self::light`]) into `t`, with its shade (see
    /// [`Slice`]: `t` is 1 outside it, before and after), and rounded into
    /// `out`, by code compiled for `isa`.
    pub(super) fn row(
        &self,
        isa: Isa,
        [ic, n]: [usize; 2],
        back: &[Option<&Slice>],
        t: (&mut [f32], &mut (usize, usize)),
        out: &mut [u16],
        scratch: &mut Scratch,
    ) {
        #[cfg(target_arch = "x86_64")]
        if isa.avx2 {
            // SAFETY: the one precondition of calling a function compiled
            // for AVX2 is that the CPU has it, and `isa.avx2` is private
            // to this module, true only where `Isa::best` found it
            // (`is_x86_feature_detected!`).
            unsafe { self.row_avx2([ic, n], back, t, out, scratch) };
            return;
        }
        let _ = isa;
        self.row_body([ic, n], back, t, out, scratch);
    }

    /// [`Self::row_body`] compiled for AVX2: the passes take eight voxels
    /// at a time (the same operations on each, so the same light as four at
    /// a time); 46 ms of rows became 38 in the 257³ cloud's sweep.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn row_avx2(
        &self,
        at: [usize; 2],
        back: &[Option<&Slice>],
        t: (&mut [f32], &mut (usize, usize)),
        out: &mut [u16],
        scratch: &mut Scratch,
    ) {
        self.row_body(at, back, t, out, scratch);
    }

    /// [`Self::light`], the row's new shade, then each voxel's light
    /// rounded into `u16` units.
    #[inline(always)]
    fn row_body(
        &self,
        [ic, n]: [usize; 2],
        back: &[Option<&Slice>],
        (t, shade): (&mut [f32], &mut (usize, usize)),
        out: &mut [u16],
        scratch: &mut Scratch,
    ) {
        // The light the ring's last slice here left, back to 1.
        if shade.0 <= shade.1 {
            t[shade.0..=shade.1].fill(1.0);
        }
        let touched = self.light(ic, n, back, t, scratch);
        *shade = NONE;
        if touched.0 <= touched.1 {
            let run = &t[touched.0..=touched.1];
            if let Some(lo) = run.iter().position(|&t| t != 1.0) {
                let hi = run.iter().rposition(|&t| t != 1.0).unwrap_or(lo);
                *shade = (touched.0 + lo, touched.0 + hi);
            }
        }
        // `+ 0.5` and truncation: rounding, without a call to `roundf`
        // (1 is `u16::MAX`).
        out.fill(u16::MAX);
        if shade.0 <= shade.1 {
            let run = shade.0..=shade.1;
            for (o, &t) in out[run.clone()].iter_mut().zip(&t[run]) {
                *o = (t.clamp(0.0, 1.0) * UNIT + 0.5) as u16;
            }
        }
    }

    /// The light reaching each voxel of row `ic` of the `n`-th slice from
    /// the light, into `t` (1 where it comes in), from the slices
    /// `back[k]` `k` back (`scratch`: a thread's buffers); returns the
    /// span of the voxels it may have changed. Each sample is one pass
    /// along the row over the voxels that take it (a run of the row), made
    /// only where it meets material (or, for the light at the last, shade):
    /// - a voxel whose ray leaves the grid no sooner than `exit_slices`
    ///   on takes the segment's samples, then the light at the last;
    /// - any other takes its samples up to the grid's face, then the
    ///   fraction of a step left, on the face (as the reference's march).
    #[inline(always)]
    fn light(
        &self,
        ic: usize,
        n: usize,
        back: &[Option<&Slice>],
        t: &mut [f32],
        Scratch { taken, face_alpha }: &mut Scratch,
    ) -> (usize, usize) {
        let [nb, nc] = self.n;
        let pb = nb + 2;
        let exit_c = Self::exit(ic, nc, self.d[1]).min(n as f64);
        let exit = |ib: usize| Self::exit(ib, nb, self.d[0]).min(exit_c);
        let exit_slices = self.exit_slices as f64;
        // The voxels whose rays leave the grid no sooner than
        // `exit_slices` on (`inner`), and the others (`band`): at most a
        // few voxels at one end of the row (the end the light's direction
        // leaves by), or the whole row where it leaves by a row's side or
        // the light's face that soon.
        let leaves = |ib: &usize| exit(*ib) < exit_slices;
        let (inner, band) = if exit_c < exit_slices {
            (None, 0..nb)
        } else if self.d[0] > 0.0 {
            let end = (0..nb).rev().find(|ib| !leaves(ib)).map_or(0, |ib| ib + 1);
            (end.checked_sub(1).map(|hi| (0, hi)), end..nb)
        } else if self.d[0] < 0.0 {
            let start = (0..nb).find(|ib| !leaves(ib)).unwrap_or(nb);
            ((start < nb).then_some((start, nb - 1)), 0..start)
        } else {
            (Some((0, nb - 1)), 0..0)
        };
        let mut touched = NONE;
        let [inner_reach, last_reach, band_reach] = &self.reach;
        let material: fn(&Slice) -> &[u32] = |s| &s.material_rows;
        if let Some(run) = inner {
            if inner_reach.meets(ic, nc, back, material) {
                for tap in &self.inner {
                    self.absorb(tap, ic, back, run, t, &mut touched);
                }
            }
            if self.weight != 1.0 && touched.0 <= touched.1 {
                (t[touched.0..=touched.1].iter_mut())
                    .for_each(|t| *t = t.max(0.0).powf(self.weight));
            }
            // The light at the last sample, where it is not 1.
            if let Some(last) = self.inner.last()
                && last_reach.meets(ic, nc, back, |s| &s.shade_rows)
                && let Some((from, to, near, far)) = self.meets(last, ic, back, |s| &s.shade, run)
            {
                let planes = (&near.light[..], far.map(|s| &s.light[..]));
                let row = (ic as isize + last.c + 1) as usize;
                let t = &mut t[from..=to];
                Self::pass(planes, last, [pb, row], from, t, |t, l| *t *= l);
                widen(&mut touched, (from, to));
            }
        }
        if band.is_empty() || !band_reach.meets(ic, nc, back, material) {
            return touched;
        }
        // The voxels of the band whose rays leave by the face `exit_c`
        // names (the light's, or a side across the rows) share their face
        // point (`shared`, beside `inner`); the few that leave by a row's
        // end first (`single`, at the row's end) do not.
        let shares = |ib: usize| Self::exit(ib, nb, self.d[0]) >= exit_c;
        let rising = self.d[0] < 0.0;
        let (shared, single) = if rising {
            let start = (band.clone()).find(|&ib| shares(ib)).unwrap_or(band.end);
            (start..band.end, band.start..start)
        } else {
            let end = (band.clone())
                .rev()
                .find(|&ib| shares(ib))
                .map_or(band.start, |ib| ib + 1);
            (band.start..end, end..band.end)
        };
        // How many samples each voxel of the band takes: those before its
        // ray leaves the grid, fewer the farther from `inner` (`exit` is
        // monotone along the row), so the voxels taking each sample are
        // the band's end beside `inner`.
        // (`exit` is not negative: truncation is the floor.)
        let samples = |exit: f64| (exit * self.per_slice + 1e-9) as usize;
        let shared_take = samples(exit_c);
        taken.clear();
        taken.resize(band.len(), shared_take);
        for ib in single.clone() {
            taken[ib - band.start] = samples(exit(ib));
        }
        for (m, tap) in (1..).zip(&self.band) {
            let run = if rising {
                let first = taken.partition_point(|&k| k < m);
                (first < taken.len()).then(|| (band.start + first, band.end - 1))
            } else {
                let count = taken.partition_point(|&k| k >= m);
                (count > 0).then(|| (band.start, band.start + count - 1))
            };
            let Some(run) = run else {
                break;
            };
            self.absorb(tap, ic, back, run, t, &mut touched);
        }
        // The fraction of a step left at the face: one pass for `shared`.
        let rest = |exit: f64, whole: usize| (exit * self.per_slice - whole as f64).max(0.0) as f32;
        let face_rest = rest(exit_c, shared_take);
        if !shared.is_empty() && face_rest > 0.0 {
            let face = Tap::at(exit_c, self.d);
            let run = (shared.start, shared.end - 1);
            if let Some((from, to, near, far)) = self.meets(&face, ic, back, |s| &s.material, run) {
                let planes = (&near.alpha[..], far.map(|s| &s.alpha[..]));
                let row = (ic as isize + face.c + 1) as usize;
                face_alpha.clear();
                face_alpha.resize(to + 1 - from, 0.0);
                Self::pass(planes, &face, [pb, row], from, face_alpha, |f, a| *f = a);
                for (t, &a) in t[from..=to].iter_mut().zip(face_alpha.iter()) {
                    if a > 0.0 {
                        *t *= (1.0 - a).max(0.0).powf(face_rest);
                    }
                }
                widen(&mut touched, (from, to));
            }
        }
        for ib in single {
            let exit = exit(ib);
            let rest = rest(exit, taken[ib - band.start]);
            if rest > 0.0 {
                let face = Tap::at(exit, self.d);
                let meets = self.meets(&face, ic, back, |s| &s.material, (ib, ib));
                let Some((_, _, near, far)) = meets else {
                    continue;
                };
                let mut alpha_face = face.bilinear(ib, ic, pb, &near.alpha);
                if let Some(far) = far {
                    let far = face.bilinear(ib, ic, pb, &far.alpha);
                    alpha_face = alpha_face * (1.0 - face.w) + far * face.w;
                }
                if alpha_face > 0.0 {
                    t[ib] *= (1.0 - alpha_face).max(0.0).powf(rest);
                    widen(&mut touched, (ib, ib));
                }
            }
        }
        touched
    }

    /// The voxels of `lo..=hi` in row `ic` whose sample at `tap` meets a
    /// voxel in the spans `spans` gives of the slices it lies between (see
    /// [`Slice`]), with those slices (the far one where it lies between
    /// two); `None` where none does.
    #[inline(always)]
    fn meets<'s>(
        &self,
        tap: &Tap,
        ic: usize,
        back: &[Option<&'s Slice>],
        spans: impl Fn(&'s Slice) -> &'s [(usize, usize)],
        (lo, hi): (usize, usize),
    ) -> Option<(usize, usize, &'s Slice, Option<&'s Slice>)> {
        let nc = self.n[1];
        let done = |k: usize| back[k].expect("a sample before the face: the slice is done");
        let near = done(tap.slices);
        let far = (tap.w > 0.0).then(|| done(tap.slices + 1));
        // The span of the slices' voxels in the rows the sample lies
        // between.
        let c0 = ic as isize + tap.c;
        let rows = c0.max(0) as usize..=((c0 + 1).max(0) as usize).min(nc - 1);
        let mut span = NONE;
        for slice in std::iter::once(near).chain(far) {
            for &row in &spans(slice)[rows.clone()] {
                widen(&mut span, row);
            }
        }
        if span.0 > span.1 {
            return None;
        }
        // The voxels whose sample's columns `ib + b`, `ib + b + 1` meet
        // the span.
        let from = (span.0 as isize - tap.b - 1).max(lo as isize) as usize;
        let to = (span.1 as isize - tap.b).min(hi as isize);
        (to >= from as isize).then_some((from, to as usize, near, far))
    }

    /// For the voxels `lo..=hi` of row `ic`, `t *= 1 − α` with `α` the
    /// opacity at `tap` from each, where it meets material, widening
    /// `touched` to the voxels it changes.
    #[inline(always)]
    fn absorb(
        &self,
        tap: &Tap,
        ic: usize,
        back: &[Option<&Slice>],
        run: (usize, usize),
        t: &mut [f32],
        touched: &mut (usize, usize),
    ) {
        if let Some((from, to, near, far)) = self.meets(tap, ic, back, |s| &s.material, run) {
            let planes = (&near.alpha[..], far.map(|s| &s.alpha[..]));
            let row = (ic as isize + tap.c + 1) as usize;
            let t = &mut t[from..=to];
            Self::pass(planes, tap, [self.n[0] + 2, row], from, t, |t, a| {
                *t *= 1.0 - a
            });
            widen(touched, (from, to));
        }
    }

    /// For each voxel `from + i` of a row, `apply(t[i], value)` with the
    /// interpolation at `tap` from it of the bordered slices `planes` (the
    /// far one where the sample lies between two; rows `pb` long, the
    /// sample's nearer row `row`): [`Tap::bilinear`]'s expression, and
    /// between slices `near·(1 − w) + far·w`, a row at a time.
    #[inline(always)]
    fn pass(
        (near, far): (&[f32], Option<&[f32]>),
        tap: &Tap,
        [pb, row]: [usize; 2],
        from: usize,
        t: &mut [f32],
        apply: impl Fn(&mut f32, f32),
    ) {
        let len = t.len();
        let x = (from as isize + tap.b + 1) as usize;
        fn bilinear<'p>(
            plane: &'p [f32],
            [wb, wc]: [f32; 2],
            start: [usize; 2],
            len: usize,
        ) -> impl Iterator<Item = f32> + 'p {
            let r0 = &plane[start[0]..][..len + 1];
            let r1 = &plane[start[1]..][..len + 1];
            (r0[..len].iter().zip(&r0[1..]))
                .zip(r1[..len].iter().zip(&r1[1..]))
                .map(move |((&a, &b), (&c, &d))| {
                    (a * (1.0 - wb) + b * wb) * (1.0 - wc) + (c * (1.0 - wb) + d * wb) * wc
                })
        }
        let rows = [row * pb + x, (row + 1) * pb + x];
        let bilinear = |plane| bilinear(plane, [tap.wb, tap.wc], rows, len);
        match far {
            None => t
                .iter_mut()
                .zip(bilinear(near))
                .for_each(|(t, v)| apply(t, v)),
            Some(far) => {
                let w = tap.w;
                (t.iter_mut().zip(bilinear(near).zip(bilinear(far))))
                    .for_each(|(t, (n, f))| apply(t, n * (1.0 - w) + f * w))
            }
        }
    }
}
