//! Up in the picture is up in the world: `volray render` of a NetCDF
//! temperature on pressure levels and of an ocean temperature on depths
//! (CF `positive = "down"`), seen from the side (the default view: from
//! +x, +z up) with an opacity ramp over the values. The files are written
//! here by netCDF4-python in `target/pyenv` (NetCDF-4 and NetCDF-3, which
//! `.ci/run` installs); without it these tests fail under `CI=true` and
//! are skipped elsewhere.
//!
//! Each volume's value depends on its vertical coordinate alone: 1 at the
//! surface (1000 hPa; depth 0), falling to 0 away from it, so every ray
//! of an image row crosses one value and the rows' brightness says where
//! the surface was drawn.

mod common;

use common::{Picture, render, stdout, volray};

/// Pressure levels 1000, 900, … 200 hPa (the ground first, `positive =
/// "down"`) over lat −80 … 80 and lon 0 … 160 by 20 degrees; ocean depth
/// 0, 100, … 800 m (`positive = "down"`) over y and x 0 … 800 m by 100.
/// The value: 1 at the surface, 0 at the far end, linear between.
const WRITE: &str = r#"
import sys
import numpy as np
import netCDF4
def coord(nc, name, values, **attrs):
    c = nc.createVariable(name, "f8", (name,))
    c[:] = values
    for k, a in attrs.items():
        c.setncattr(k, a)
n = 9
surface_first = np.linspace(1.0, 0.0, n)[:, None, None] * np.ones((n, n, n))
for fmt, name in [("NETCDF4", "pressure.nc"), ("NETCDF3_CLASSIC", "pressure3.nc")]:
    with netCDF4.Dataset(sys.argv[1] + "/" + name, "w", format=fmt) as nc:
        for d in ["level", "lat", "lon"]:
            nc.createDimension(d, n)
        coord(nc, "level", 1000.0 - 100.0 * np.arange(n), units="hPa", positive="down",
              standard_name="air_pressure")
        coord(nc, "lat", -80.0 + 20.0 * np.arange(n), units="degrees_north")
        coord(nc, "lon", 20.0 * np.arange(n), units="degrees_east")
        t = nc.createVariable("t", "f4", ("level", "lat", "lon"))
        t[:] = surface_first
with netCDF4.Dataset(sys.argv[1] + "/ocean.nc", "w", format="NETCDF4") as nc:
    for d in ["depth", "y", "x"]:
        nc.createDimension(d, n)
    coord(nc, "depth", 100.0 * np.arange(n), units="m", positive="down")
    coord(nc, "y", 100.0 * np.arange(n), units="m", axis="Y")
    coord(nc, "x", 100.0 * np.arange(n), units="m", axis="X")
    t = nc.createVariable("temp", "f4", ("depth", "y", "x"))
    t[:] = surface_first
"#;

fn files() -> Option<tempfile::TempDir> {
    common::written_by_python(&["netCDF4", "numpy"], &[], WRITE)
}

/// An opacity ramp (0 at the lowest value, 1 at the highest), grey, no
/// lighting: a row's brightness grows with its value.
const LOOK: [&str; 8] = [
    "--opacity",
    "0,1",
    "--colormap",
    "grey",
    "--no-shading",
    "--size",
    "64",
    "--range",
];

/// The brightness (sum of R, G, B) of the centre column's pixels, top
/// row first, and the row where it is brightest (the first, if several).
fn column(p: &Picture) -> (Vec<u32>, usize) {
    let c = p.width / 2;
    let rows: Vec<u32> = (0..p.height)
        .map(|r| p.at(c, r).iter().map(|&v| v as u32).sum())
        .collect();
    let max = *rows.iter().max().unwrap();
    let at = rows.iter().position(|&v| v == max).unwrap();
    (rows, at)
}

#[test]
fn pressure_levels_seen_from_the_side_have_the_ground_at_the_bottom() {
    let Some(dir) = files() else { return };
    for name in ["pressure.nc", "pressure3.nc"] {
        let input = dir.path().join(name);
        let input = input.to_str().unwrap();
        let png = dir.path().join(format!("{name}.png"));
        render(&[&[input], &LOOK[..], &["0,1"]].concat(), &png);
        // The surface (value 1, opaque white) at the bottom of the volume,
        // the top of the atmosphere (value 0, transparent) above it.
        let (rows, brightest) = column(&Picture::read(&png));
        assert!(rows[brightest] > 500, "{name}: {rows:?}");
        assert!(
            brightest > 3 * rows.len() / 4,
            "{name}: brightest row {brightest} of {rows:?}"
        );
        let lit: Vec<usize> = (0..rows.len()).filter(|&r| rows[r] > 0).collect();
        assert!(
            lit.windows(2).all(|w| rows[w[0]] <= rows[w[1]]),
            "{name}: brighter towards the ground: {rows:?}"
        );

        let info = volray(&["info", input, "--json"]);
        assert!(info.status.success());
        let v: serde_json::Value = serde_json::from_str(&stdout(&info)).unwrap();
        assert_eq!(v["origin"][2], -1000.0, "{name}");
        assert_eq!(v["spacing"][2], 100.0, "{name}");
        let notes = v["notes"].to_string();
        assert!(
            notes.contains("z (level) points down (positive = \\\"down\\\")")
                && notes.contains("level 1000 lowest, 200 highest"),
            "{name}: {notes}"
        );
    }
}

#[test]
fn ocean_depth_seen_from_the_side_has_the_surface_at_the_top() {
    let Some(dir) = files() else { return };
    let input = dir.path().join("ocean.nc");
    let input = input.to_str().unwrap();
    let png = dir.path().join("ocean.png");
    render(&[&[input], &LOOK[..], &["0,1"]].concat(), &png);
    // The surface (value 1) on top, the seabed (value 0) at the bottom.
    let (rows, brightest) = column(&Picture::read(&png));
    assert!(rows[brightest] > 500, "{rows:?}");
    assert!(
        brightest < rows.len() / 2,
        "brightest row {brightest} of {rows:?}"
    );
    let lit: Vec<usize> = (0..rows.len()).filter(|&r| rows[r] > 0).collect();
    assert!(
        lit.windows(2).all(|w| rows[w[0]] >= rows[w[1]]),
        "darker towards the seabed: {rows:?}"
    );

    let info = volray(&["info", input, "--json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&info)).unwrap();
    assert_eq!(v["origin"][2], -800.0);
    assert_eq!(v["length_unit"], "m");
    assert!(
        v["notes"]
            .to_string()
            .contains("depth 800 lowest, 0 highest")
    );
}
