//! CCP4 maps of skewed cells that are not one whole cell
//! (`fixtures/make_crystal_map_fixtures.py`: written by mrcfile, their
//! geometry checked by gemmi). The map's own box is resampled onto an
//! axis-aligned grid; outside it the volume is NaN, marked empty.
//!
//! Every map holds `c + 10r + 100s` at column c, row r, section s: linear,
//! so trilinear resampling reproduces it exactly inside the box.

mod common;

use volray_core::glam::{DMat3, DVec3};
use volray_io::{ReadOptions, VolumeFormat, read};

/// A map as the fixture script wrote it, with gemmi's orthogonalisation
/// matrix (rows x, y, z) and its positions of the first and last points.
struct Map {
    name: &'static str,
    orth: [[f64; 3]; 3],
    m: [f64; 3],
    n: [usize; 3],
    start: [f64; 3],
    /// The crystal axis (0 X, 1 Y, 2 Z) of columns, rows, sections.
    axes: [usize; 3],
    first: [f64; 3],
    last: [f64; 3],
}

const MAPS: [Map; 3] = [
    Map {
        name: "part_monoclinic.ccp4",
        orth: [
            [8.0, 0.0, -3.420201433256687],
            [0.0, 9.0, 0.0],
            [0.0, 0.0, 9.396926207859085],
        ],
        m: [8.0, 9.0, 10.0],
        n: [4, 3, 5],
        start: [2.0, 1.0, 3.0],
        axes: [0, 1, 2],
        first: [0.973939570022994, 1.0, 2.8190778623577253],
        last: [2.605858996720319, 3.0, 6.577848345501359],
    },
    Map {
        name: "part_triclinic.ccp4",
        orth: [
            [6.0, -2.9583278321848954, -1.3891854213354424],
            [0.0, 6.34415450925655, 0.8850087186801386],
            [0.0, 0.0, 7.828596517448655],
        ],
        m: [12.0, 14.0, 16.0],
        n: [3, 4, 5],
        start: [-2.0, 3.0, 1.0],
        axes: [1, 2, 0],
        first: [0.6621459952403038, -0.7403686522841241, 1.4678618470216227],
        last: [1.979055466999209, 0.331878269505052, 2.9357236940432454],
    },
    Map {
        name: "two_cells.ccp4",
        orth: [
            [4.0, 0.0, -0.6945927106677212],
            [0.0, 4.0, 0.0],
            [0.0, 0.0, 3.939231012048832],
        ],
        m: [4.0, 4.0, 4.0],
        n: [9, 5, 5],
        start: [0.0, 0.0, 0.0],
        axes: [0, 1, 2],
        first: [0.0, 0.0, 0.0],
        last: [7.305407289332279, 4.0, 3.939231012048832],
    },
];

impl Map {
    /// The file coordinates (c, r, s) of world position `p`, by gemmi's
    /// conventions: fractional = orth⁻¹ p, grid index = fractional · M,
    /// file coordinate = index − START along the axis it runs along.
    fn file_coords(&self, p: DVec3) -> DVec3 {
        let o = self.orth;
        let orth = DMat3::from_cols(
            DVec3::new(o[0][0], o[1][0], o[2][0]),
            DVec3::new(o[0][1], o[1][1], o[2][1]),
            DVec3::new(o[0][2], o[1][2], o[2][2]),
        );
        let frac = orth.inverse() * p;
        let index = frac * DVec3::from(self.m);
        DVec3::new(
            index[self.axes[0]] - self.start[0],
            index[self.axes[1]] - self.start[1],
            index[self.axes[2]] - self.start[2],
        )
    }
}

#[test]
fn skewed_maps_of_part_of_a_cell_or_more_resample_their_own_box() {
    for map in &MAPS {
        let path = common::fixture("mrc", map.name);
        let l =
            read(&path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", map.name));
        assert_eq!(l.format, VolumeFormat::Mrc);
        assert!(l.info.nan_is_empty, "{}", map.name);
        common::assert_note(&l, "not periodic, so only its own box is resampled");
        common::assert_note(&l, "are NaN (empty space, no data)");
        let v = &l.volume;
        // The box's corners, gemmi's first and last points, lie in the volume.
        let (lo, hi) = v.bounds();
        for p in [map.first, map.last].map(DVec3::from) {
            assert!(
                p.cmpge(lo - 1e-9).all() && p.cmple(hi + 1e-9).all(),
                "{}: {p} outside {lo}..{hi}",
                map.name
            );
        }
        let last = map.n.map(|n| (n - 1) as f64);
        let (mut inside, mut outside) = (0, 0);
        let [nx, ny, nz] = v.dims();
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let g = map.file_coords(v.world_position(i, j, k));
                    let got = v.get(i, j, k);
                    let margin = (0..3)
                        .map(|a| g[a].min(last[a] - g[a]))
                        .fold(f64::INFINITY, f64::min);
                    if margin > 1e-6 {
                        let want = g.x + 10.0 * g.y + 100.0 * g.z;
                        assert!(
                            (f64::from(got) - want).abs() < 1e-3,
                            "{} ({i}, {j}, {k}): {got} vs {want}",
                            map.name
                        );
                        inside += 1;
                    } else if margin < -1e-6 {
                        assert!(got.is_nan(), "{} ({i}, {j}, {k}) outside: {got}", map.name);
                        outside += 1;
                    }
                }
            }
        }
        assert!(
            inside >= 5 && outside >= 5,
            "{}: {inside} inside, {outside} outside",
            map.name
        );
    }
}

#[test]
fn the_finest_step_is_the_spacing() {
    // Each axis of the bounding box is cut into whole steps of about the
    // finest file step, so the spacing is within half a step's share of
    // it. Monoclinic part: steps of 1 angstrom along a, b and c.
    let l = read(
        &common::fixture("mrc", "part_monoclinic.ccp4"),
        &ReadOptions::default(),
    )
    .unwrap();
    let s = l.volume.spacing();
    assert!((s - DVec3::ONE).abs().max_element() < 0.1, "{s}");
    // Triclinic: 0.5 angstrom steps.
    let l = read(
        &common::fixture("mrc", "part_triclinic.ccp4"),
        &ReadOptions::default(),
    )
    .unwrap();
    let s = l.volume.spacing();
    assert!((s - DVec3::splat(0.5)).abs().max_element() < 0.1, "{s}");
}
