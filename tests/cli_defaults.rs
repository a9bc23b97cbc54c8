//! The picture a file gets with no options where its file says what it
//! is (issue 43 item 8): a CT in Hounsfield units drawn with the CT look
//! (`--preset ct-bone`: its bone, not its soft tissue), and axes in
//! different units (degrees by metres) drawn as a box, not a line
//! (volray-app's `display.rs`, `--scale`). The files are written at test
//! time by pydicom, netCDF4 and zarr-python, or here (a MetaImage).

use std::path::Path;

mod common;
use common::{Picture, render, stderr, stdout, volray, written_by_python};

/// A CT series of 24 slices of 24², 1 mm apart, written by pydicom:
/// stored uint16 with RescaleIntercept −1024 (HU = stored − 1024), air
/// (−1000 HU) around a 20 mm cube of soft tissue (40 HU) centred in the
/// grid, holding a ball of bone (1200 HU) of radius 4 mm at its centre.
const CT: &str = r#"
import sys, numpy as np, pydicom
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.uid import ExplicitVRLittleEndian, generate_uid, CTImageStorage
out = sys.argv[1]
n = 24
k, j, i = np.mgrid[0:n, 0:n, 0:n].astype(float)
c = (n - 1) / 2
hu = np.full((n, n, n), -1000.0)
inside = (abs(i - c) <= 10) & (abs(j - c) <= 10) & (abs(k - c) <= 10)
hu[inside] = 40.0
hu[(i - c) ** 2 + (j - c) ** 2 + (k - c) ** 2 <= 16] = 1200.0
stored = (hu + 1024).astype(np.uint16)
series, study = generate_uid(), generate_uid()
for z in range(n):
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = CTImageStorage
    meta.MediaStorageSOPInstanceUID = generate_uid()
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = Dataset()
    ds.file_meta = meta
    ds.SOPClassUID = CTImageStorage
    ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
    ds.StudyInstanceUID, ds.SeriesInstanceUID = study, series
    ds.Modality = "CT"
    ds.InstanceNumber = z + 1
    ds.ImagePositionPatient = [0, 0, z]
    ds.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
    ds.PixelSpacing = [1, 1]
    ds.SliceThickness = 1
    ds.Rows = ds.Columns = n
    ds.SamplesPerPixel = 1
    ds.PhotometricInterpretation = "MONOCHROME2"
    ds.BitsAllocated = ds.BitsStored = 16
    ds.HighBit = 15
    ds.PixelRepresentation = 0
    ds.RescaleIntercept = -1024
    ds.RescaleSlope = 1
    ds.PixelData = stored[z].tobytes()
    ds.save_as(f"{out}/ct{z:02}.dcm", enforce_file_format=True)
"#;

/// The columns and rows a picture covers (pixels not the background),
/// as (count, width, height).
fn footprint(p: &Picture) -> (usize, usize, usize) {
    let background = p.rgb[0];
    let (mut cols, mut rows, mut count) = (Vec::new(), Vec::new(), 0);
    for row in 0..p.height {
        for col in 0..p.width {
            if p.at(col, row)
                .iter()
                .zip(background)
                .any(|(a, b)| a.abs_diff(b) > 2)
            {
                cols.push(col);
                rows.push(row);
                count += 1;
            }
        }
    }
    let span = |v: &[usize]| match (v.iter().min(), v.iter().max()) {
        (Some(lo), Some(hi)) => hi - lo + 1,
        _ => 0,
    };
    (count, span(&cols), span(&rows))
}

#[test]
fn a_ct_with_no_options_shows_its_bone_and_not_its_soft_tissue() {
    let Some(dir) = written_by_python(&["pydicom", "numpy"], &[], CT) else {
        return;
    };
    let series = dir.path().to_str().unwrap();
    let info = volray(&["info", series, "--json"]);
    let doc: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert_eq!(doc["modality"], "CT", "{}", stderr(&info));

    let out = tempfile::tempdir().unwrap();
    let png = |name: &str| out.path().join(name);
    let said = render(&[series, "--size", "64"], &png("ct.png"));
    assert!(
        said.contains(
            "drawn with --preset ct-bone; --tf auto for the look chosen from the histogram"
        ),
        "{said}"
    );
    // The look is the preset's, to the bit.
    render(
        &[series, "--size", "64", "--preset", "ct-bone"],
        &png("bone.png"),
    );
    let default = Picture::read(&png("ct.png"));
    assert_eq!(default, Picture::read(&png("bone.png")));
    // `--tf auto` given keeps the histogram's choice, and says nothing.
    let said = render(&[series, "--size", "64", "--tf", "auto"], &png("auto.png"));
    assert!(!said.contains("ct-bone"), "{said}");

    // The soft tissue's look (`--preset ct-soft-tissue`) shows the cube:
    // 21 mm wide (its voxels' centres 20 mm apart, half a voxel more each
    // side), the ruler; the CT look shows the ball of radius 4 mm alone,
    // its disc about 9 mm across at the same scale (orthographic, the
    // same box framed alike).
    render(
        &[series, "--size", "64", "--preset", "ct-soft-tissue"],
        &png("soft.png"),
    );
    let (_, slab_w, slab_h) = footprint(&Picture::read(&png("soft.png")));
    let (count, ball_w, ball_h) = footprint(&default);
    let px_per_mm = slab_w as f64 / 21.0;
    assert!(slab_w > 40 && slab_h > 40, "slab {slab_w} x {slab_h}");
    for side in [ball_w, ball_h] {
        let mm = side as f64 / px_per_mm;
        assert!(
            (7.0..=10.5).contains(&mm),
            "ball {ball_w} x {ball_h} px, {mm} mm"
        );
    }
    // A disc: about π/4 of its bounding square covered.
    let disc = count as f64 / (ball_w * ball_h) as f64;
    assert!((0.6..=0.95).contains(&disc), "{disc}");
    // Bone in the CT look's colours: ivory to white, lit.
    let centre = default.at(default.width / 2, default.height / 2);
    assert!(
        centre[0] > 100 && centre[0] >= centre[1] && centre[1] >= centre[2],
        "{centre:?}"
    );
}

#[test]
fn a_ct_without_bone_keeps_the_histograms_look() {
    // The CT fixture: modality CT, values −1424 to −578 HU (no bone):
    // the CT look would draw nothing, so the histogram's choice stays.
    let ct = "crates/io/tests/fixtures/dicom/ct";
    let out = tempfile::tempdir().unwrap();
    let png = out.path().join("ct.png");
    let said = render(&[ct, "--size", "32"], &png);
    assert!(!said.contains("ct-bone"), "{said}");
    let (count, _, _) = footprint(&Picture::read(&png));
    assert!(count > 0);
}

/// A CF file written by netCDF4: t(level, lat, lon) with lon 10 to 19
/// degrees_east (10 points), lat 40 to 47 degrees_north (8), level 0 to
/// 3000 m (6, positive up); t = 1 + lon index + lat index + level index.
const CF: &str = r#"
import sys, numpy as np, netCDF4
with netCDF4.Dataset(sys.argv[1] + "/cf.nc", "w") as f:
    for name, n in [("level", 6), ("lat", 8), ("lon", 10)]:
        f.createDimension(name, n)
    lon = f.createVariable("lon", "f8", ("lon",)); lon.units = "degrees_east"; lon[:] = 10 + np.arange(10)
    lat = f.createVariable("lat", "f8", ("lat",)); lat.units = "degrees_north"; lat[:] = 40 + np.arange(8)
    lev = f.createVariable("level", "f8", ("level",)); lev.units = "m"; lev.positive = "up"; lev[:] = 600 * np.arange(6)
    t = f.createVariable("t", "f4", ("level", "lat", "lon"))
    k, j, i = np.mgrid[0:6, 0:8, 0:10]
    t[:] = 1.0 + i + j + k
"#;

#[test]
fn degrees_by_metres_are_drawn_as_a_box_with_a_note_and_scale_one_draws_them_as_stored() {
    let Some(dir) = written_by_python(&["netCDF4", "numpy"], &[], CF) else {
        return;
    };
    let cf = dir.path().join("cf.nc");
    let cf = cf.to_str().unwrap();
    let out = tempfile::tempdir().unwrap();
    let png = |name: &str| out.path().join(name);
    // From the side (the default eye on +x): lat across, level up.
    let note = "z (level, m) drawn at 1 m = 0.0027 degrees_east: axes in different units, each drawn to span about the mean extent of x, y (lon, lat); --scale 1,1,0.0027 is this stretch, --scale 1,1,1 draws them as stored";
    let said = render(&[cf, "--size", "48"], &png("side.png"));
    assert!(said.contains(note), "{said}");
    let info = volray(&["info", cf, "--json"]);
    let doc: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    let notes = doc["notes"].as_array().unwrap();
    assert!(notes.iter().any(|n| n == note), "{notes:?}");
    // The stored spacing is shown as stored.
    assert_eq!(doc["spacing"], serde_json::json!([1.0, 1.0, 600.0]));

    // (9 + 7) / 2 = 8 degrees over 3000 m: 0.00267 to two digits.
    let (count, w, h) = footprint(&Picture::read(&png("side.png")));
    assert!(count > 0 && w > 15 && h > 15, "{w} x {h}");

    // --scale with the note's factor is the same picture, to the bit.
    render(
        &[cf, "--size", "48", "--scale", "1,1,0.0027"],
        &png("given.png"),
    );
    assert_eq!(
        Picture::read(&png("side.png")),
        Picture::read(&png("given.png"))
    );
    // --scale 1,1,1: as stored, 7 degrees across 3000 m tall, a line.
    let said = render(
        &[cf, "--size", "48", "--scale", "1,1,1"],
        &png("stored.png"),
    );
    assert!(!said.contains("drawn at"), "{said}");
    let (_, w, _) = footprint(&Picture::read(&png("stored.png")));
    assert!(w <= 2, "{w}");

    // The reference renderer agrees with the fast path under a scale.
    let scaled = ["--size", "32", "--scale", "1,1,0.005"];
    render(&[&[cf][..], &scaled[..]].concat(), &png("fast.png"));
    let reference = [&[cf][..], &scaled[..], &["--reference"][..]].concat();
    render(&reference, &png("reference.png"));
    let (fast, exact) = (
        Picture::read(&png("fast.png")),
        Picture::read(&png("reference.png")),
    );
    assert!(footprint(&fast).0 > 0);
    assert!(fast.max_diff(&exact) <= 1, "{}", fast.max_diff(&exact));
}

#[test]
fn a_file_in_one_length_unit_is_not_stretched() {
    // NRRD in one unit (mm), however long one axis: as stored, no note.
    let nrrd = Path::new("crates/io/tests/fixtures/nrrd");
    let any = std::fs::read_dir(nrrd)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "nrrd"))
        .unwrap();
    let out = tempfile::tempdir().unwrap();
    let said = render(
        &[any.to_str().unwrap(), "--size", "16"],
        &out.path().join("a.png"),
    );
    assert!(!said.contains("drawn at"), "{said}");
}

/// A Zarr array of 64 × 64 × 32 (x, y, z) written by zarr-python: a
/// Gaussian blob in chunks of 16 × 16 × 8.
const ZARR: &str = r#"
import sys, numpy as np, zarr
k, j, i = np.mgrid[0:32, 0:64, 0:64]
a = np.exp(-((i - 32) ** 2 + (j - 32) ** 2 + (k - 16) ** 2) / 200.0).astype(np.float32)
z = zarr.open_array(sys.argv[1] + "/z.zarr", mode="w", shape=a.shape, chunks=(8, 16, 16), dtype="f4", zarr_format=2)
z[:] = a
# The same as an OME-Zarr image whose y and x are in degrees, z in metres.
g = zarr.open_group(sys.argv[1] + "/o.zarr", mode="w", zarr_format=2)
g.create_array("0", shape=a.shape, chunks=(8, 16, 16), dtype="f4")[:] = a
g.attrs["multiscales"] = [{"version": "0.4", "axes": [
    {"name": "z", "type": "space", "unit": "meter"},
    {"name": "y", "type": "space", "unit": "degree"},
    {"name": "x", "type": "space", "unit": "degree"}],
  "datasets": [{"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [100.0, 0.25, 0.25]}]}]}]
"#;

#[test]
fn a_level_rendered_in_pieces_is_stretched_as_it_is_whole_as_given_or_by_default() {
    let Some(dir) = written_by_python(&["zarr", "numpy"], &[], ZARR) else {
        return;
    };
    let store = dir.path().join("z.zarr");
    let store = store.to_str().unwrap();
    let out = tempfile::tempdir().unwrap();
    let png = |name: &str| out.path().join(name);
    let scaled = [store, "--size", "48", "--scale", "1,1,3"];
    render(&scaled, &png("whole.png"));
    // Under 600 KiB the level (626 KiB whole) is rendered in two pieces.
    let pieces = [&scaled[..], &["--max-memory", "600K"][..]].concat();
    let said = render(&pieces, &png("pieces.png"));
    assert!(said.contains("rendered in pieces"), "{said}");
    render(
        &[store, "--size", "48", "--max-memory", "600K"],
        &png("as_stored.png"),
    );
    let (whole, in_pieces) = (
        Picture::read(&png("whole.png")),
        Picture::read(&png("pieces.png")),
    );
    assert_eq!(whole.max_diff(&in_pieces), 0);
    assert!(in_pieces.max_diff(&Picture::read(&png("as_stored.png"))) > 50);

    // The default stretch of degrees by metres, in pieces as whole: 15.75
    // degrees across, 3100 m drawn 15.75 degrees tall (0.0051 per m).
    let ome = dir.path().join("o.zarr");
    let ome = ome.to_str().unwrap();
    let note = "z (z, meter) drawn at 1 meter = 0.0051 degree";
    let said = render(&[ome, "--size", "48"], &png("ome_whole.png"));
    assert!(said.contains(note), "{said}");
    let said = render(
        &[ome, "--size", "48", "--max-memory", "600K"],
        &png("ome_pieces.png"),
    );
    assert!(
        said.contains(note) && said.contains("rendered in pieces"),
        "{said}"
    );
    let whole = Picture::read(&png("ome_whole.png"));
    assert_eq!(whole.max_diff(&Picture::read(&png("ome_pieces.png"))), 0);
    let (count, w, h) = footprint(&whole);
    assert!(count > 0 && w > 10 && h > 10, "{w} x {h}");
}

/// A MetaImage of 8³ int16 Hounsfield values (air, a ball of bone of
/// radius 2.5 at the centre), its header naming `modality`.
fn metaimage(dir: &Path, modality: &str) -> String {
    let mut bytes = format!(
        "ObjectType = Image\nNDims = 3\nDimSize = 8 8 8\nElementType = MET_SHORT\nElementSpacing = 1 1 1\nElementByteOrderMSB = False\nModality = {modality}\nElementDataFile = LOCAL\n"
    )
    .into_bytes();
    for k in 0..8 {
        for j in 0..8 {
            for i in 0..8 {
                let r2 = [i, j, k]
                    .map(|v: i32| (v as f64 - 3.5).powi(2))
                    .iter()
                    .sum::<f64>();
                let hu: i16 = if r2 <= 6.25 { 1000 } else { -1000 };
                bytes.extend(hu.to_le_bytes());
            }
        }
    }
    let path = dir.join(format!("{modality}.mha"));
    std::fs::write(&path, bytes).unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn a_metaimage_ct_gets_the_ct_look_and_an_mr_does_not() {
    let dir = tempfile::tempdir().unwrap();
    let (ct, mr) = (
        metaimage(dir.path(), "MET_MOD_CT"),
        metaimage(dir.path(), "MET_MOD_MR"),
    );
    let info = volray(&["info", &ct]);
    assert!(stdout(&info).contains("modality:  CT"), "{}", stdout(&info));
    let info = volray(&["info", &mr, "--json"]);
    let doc: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert_eq!(doc["modality"], "MR");
    let out = dir.path().join("out.png");
    assert!(render(&[&ct, "--size", "16"], &out).contains("--preset ct-bone"));
    assert!(!render(&[&mr, "--size", "16"], &out).contains("ct-bone"));
}
