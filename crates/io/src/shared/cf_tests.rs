//! The unit tests of `cf.rs`: layouts, spacing, orientation and packing
//! of hand-made variables.

use super::*;

fn var(name: &str, dims: &[(&str, u64)], attrs: &[(&str, Value)]) -> Variable {
    Variable {
        name: name.into(),
        dims: dims.iter().map(|d| d.0.to_string()).collect(),
        shape: dims.iter().map(|d| d.1).collect(),
        attrs: attrs
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect(),
        type_name: "float32".into(),
        integer: false,
    }
}

#[test]
fn x_is_the_last_dimension_and_time_holds_the_frames() {
    let t = Value::Text("T".into());
    let vars = vec![
        var("time", &[("time", 3)], &[("axis", t)]),
        var("rho", &[("time", 3), ("a", 4), ("b", 5), ("c", 6)], &[]),
    ];
    let l = layout(Path::new("f.nc"), &vars[1], &vars, Some(2)).unwrap();
    assert_eq!(l.spatial, [3, 2, 1]);
    assert_eq!((l.frame_dim, l.frames, l.frame), (Some(0), 3, 2));
    assert_eq!(l.fastest_first(), [3, 2, 1]);
    assert!(layout(Path::new("f.nc"), &vars[1], &vars, Some(3)).is_err());
}

#[test]
fn named_dimensions_win_over_their_place() {
    let vars = vec![var("v", &[("lon", 4), ("lat", 5), ("lev", 6)], &[])];
    let l = layout(Path::new("f.nc"), &vars[0], &vars, None).unwrap();
    assert_eq!(l.spatial, [0, 1, 2]);
    assert_eq!(l.fastest_first(), [2, 1, 0]);
}

#[test]
fn spacing_must_be_even_and_may_decrease() {
    assert_eq!(even_spacing(&[5.0, 3.0, 1.0]), Ok((5.0, -2.0)));
    assert!(
        even_spacing(&[0.0, 1.0, 3.0])
            .unwrap_err()
            .contains("unevenly")
    );
}

#[test]
fn packing_maps_fill_and_range_to_nan() {
    let v = var(
        "v",
        &[("x", 2)],
        &[
            ("scale_factor", Value::Numbers(vec![0.5])),
            ("add_offset", Value::Numbers(vec![10.0])),
            ("_FillValue", Value::Numbers(vec![-1.0])),
            ("valid_max", Value::Numbers(vec![100.0])),
        ],
    );
    let p = Packing::of(Path::new("f.nc"), &v).unwrap();
    assert_eq!(p.real(4.0), 12.0);
    assert!(p.real(-1.0).is_nan());
    assert!(p.real(101.0).is_nan());
}

/// Places `v(lev, lat, lon)` whose coordinate variables hold `lev`,
/// `lat` and `lon` with the attributes given.
fn place_levels(
    lev: (&[f64], &[(&str, Value)]),
    lat: (&[f64], &[(&str, Value)]),
    lon: (&[f64], &[(&str, Value)]),
) -> (Placement, FileInfo) {
    let dims = [
        ("lev", lev.0.len() as u64),
        ("lat", lat.0.len() as u64),
        ("lon", lon.0.len() as u64),
    ];
    let vars = vec![
        var("lev", &dims[..1], lev.1),
        var("lat", &dims[1..2], lat.1),
        var("lon", &dims[2..], lon.1),
        var("v", &dims, &[]),
    ];
    let values = |name: &str| -> Vec<f64> {
        match name {
            "lev" => lev.0.to_vec(),
            "lat" => lat.0.to_vec(),
            _ => lon.0.to_vec(),
        }
    };
    let l = layout(Path::new("f.nc"), &vars[3], &vars, None).unwrap();
    let mut info = FileInfo::default();
    let p = place(
        Path::new("f.nc"),
        &vars[3],
        &vars,
        &l,
        &mut |c| Ok(values(&c.name)),
        &mut info,
    )
    .unwrap();
    (p, info)
}

fn text(t: &str) -> Value {
    Value::Text(t.into())
}

#[test]
fn pressure_levels_are_placed_with_high_pressure_lowest() {
    // Stored 1000, 850, 700 hPa: z = −p runs −1000, −850, −700, upward.
    for attrs in [
        &[("units", text("hPa")), ("positive", text("down"))][..],
        &[("units", text("hPa"))][..],
        &[
            ("standard_name", text("air_pressure")),
            ("units", text("Pa")),
        ][..],
    ] {
        let (p, info) = place_levels(
            (&[1000.0, 850.0, 700.0], attrs),
            (&[0.0, 1.0], &[("units", text("degrees_north"))]),
            (&[0.0, 2.0], &[("units", text("degrees_east"))]),
        );
        assert_eq!(p.steps[2], DVec3::Z * 150.0, "{attrs:?}");
        assert_eq!(p.origin.z, -1000.0);
        assert_eq!(p.length_unit, None);
        assert!(
            info.notes
                .iter()
                .any(|n| n.contains("placed at z = −lev")
                    && n.contains("lev 1000 lowest, 700 highest")),
            "{:?}",
            info.notes
        );
    }
    // positive = "up" is taken at its word, and so are heights.
    let (p, _) = place_levels(
        (
            &[1000.0, 850.0, 700.0],
            &[("units", text("hPa")), ("positive", text("up"))],
        ),
        (&[0.0, 1.0], &[]),
        (&[0.0, 2.0], &[]),
    );
    assert_eq!((p.steps[2], p.origin.z), (DVec3::Z * -150.0, 1000.0));
}

#[test]
fn ocean_depth_puts_the_surface_on_top_and_lengths_meet_in_the_finest_unit() {
    let (p, info) = place_levels(
        (
            &[0.0, 50.0, 100.0],
            &[("units", text("m")), ("positive", text("down"))],
        ),
        (&[0.0, 2.0], &[("units", text("km"))]),
        (&[0.0, 0.5], &[("units", text("km"))]),
    );
    // Depth 0 at z = 0, the top; 100 m at z = −100, below it.
    assert_eq!(p.steps[2], DVec3::Z * -50.0);
    assert_eq!(p.origin, DVec3::ZERO);
    // x and y in km become m, exactly.
    assert_eq!(p.steps[0], DVec3::X * 500.0);
    assert_eq!(p.steps[1], DVec3::Y * 2000.0);
    assert_eq!(p.length_unit.as_deref(), Some("m"));
    assert!(
        info.notes.iter().any(|n| n
            == "x (lon)/y (lat) in km, z (lev) in m: spacing in m (x (lon) × 1000, y (lat) × 1000)"),
        "{:?}",
        info.notes
    );
}
