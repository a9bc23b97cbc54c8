//! BigDataViewer HDF5 (Fiji's BigDataViewer, BigStitcher, npy2bdv): a
//! `dataset.xml` (SpimData, `xml.rs`) beside an HDF5 file holding
//! `t{T:05}/s{S:02}/{L}/cells`, each a level of one view setup at one
//! time point, stored (z, y, x) with x fastest, with the levels'
//! downsampling factors in `s{S:02}/resolutions` (x, y, z per level) and
//! their chunks in `s{S:02}/subdivisions`.
//!
//! Read as a multiscale image of several channels and time points, the
//! same way as an OME-Zarr image (`volray_io::open_lazy`, and so the
//! level choice and piece-by-piece rendering of the front ends):
//! - **view setups** are the channels (`--channel`, by their order of
//!   ids), **time points** the time points (`--frame`), **levels** the
//!   levels (`--level`, 0 the finest);
//! - **where it lies**: the view's registration (its `ViewTransform`s
//!   composed) maps level-0 voxels to BigDataViewer's world; where it is
//!   a positive scaling and translation (no rotation), and the setup's
//!   `voxelSize` is proportional to the scaling (BigStitcher's
//!   "calibration" transform), the world is taken in the voxel size's
//!   unit: spacing = voxelSize, origin = translation × voxelSize /
//!   scaling. A coarser level of factors f lies as BigDataViewer's
//!   mipmap transform places it: spacing × f, its first voxel's centre
//!   at (f − 1) / 2 level-0 voxels;
//! - **samples**: BigDataViewer stores unsigned 16-bit data in int16
//!   datasets and reads them back as unsigned: so are they read here
//!   (kept as `f32`, values exact); other types as stored.
//!
//! The `.h5` alone opens too (its XML found beside it by name where there
//! is one; else the setups and time points from its groups, at spacing
//! 1). Rotated or sheared registrations (registered tiles and angles) and
//! other image loaders (N5, Zarr) are refused, naming what they are.

mod xml;

pub(crate) use self::xml::sniff;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use volray_core::glam::DVec3;

use super::hdf5::{Opened, read_opened};
use super::hdf5_axes::{Placement, Role};
use super::hdf5_lazy::RealValue;
use crate::error::IoError;
use crate::shared::hdf5::{self as h5, numeric_type, read_small};
use crate::{AxisNames, FileInfo, LevelInfo, Loaded, ReadOptions, VolumeFormat, Volumes};

/// Whether the HDF5 file at `path` holds BigDataViewer's layout: a group
/// `s00` with its `resolutions`, and a group `t00000`.
pub(crate) fn is_bdv_h5(path: &Path) -> bool {
    h5::open(path).is_ok_and(|h5| {
        h5.file.dataset("s00/resolutions").is_ok() && h5.file.group("t00000").is_ok()
    })
}

/// Reads the level, time point and view setup `opts` names, whole.
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let (o, real) = open(path, opts)?;
    let steps = o.axis_steps();
    let real = real.as_deref().map(|f| f as &dyn Fn(f64) -> f64);
    read_opened(o, real, steps, VolumeFormat::Bdv, opts)
}

/// The level, time point and view setup `opts` names, as a source of
/// boxes, as `hdf5.rs`'s `lazy_opened` takes a dataset.
pub(crate) fn open_lazy(
    path: &Path,
    opts: &ReadOptions,
) -> Result<Option<(super::hdf5_lazy::H5Source, FileInfo)>, IoError> {
    let (o, real) = open(path, opts)?;
    super::hdf5::lazy_opened(o, real, opts)
}

/// Where the data is and what it holds: from the XML, or from the HDF5
/// file's groups.
struct Dataset {
    /// The file that describes the views (the XML, or the `.h5` alone).
    described_by: PathBuf,
    h5_path: PathBuf,
    setups: Vec<xml::Setup>,
    timepoints: Vec<usize>,
    registrations: std::collections::HashMap<(usize, usize), [[f64; 4]; 3]>,
    notes: Vec<String>,
}

fn dataset(path: &Path) -> Result<Dataset, IoError> {
    let is_h5 = h5::open(path).is_ok();
    let xml_path = if is_h5 {
        Some(path.with_extension("xml")).filter(|p| p.is_file())
    } else {
        Some(path.to_path_buf())
    };
    if let Some(xml_path) = xml_path {
        let fail =
            |reason: String| IoError::invalid(&xml_path, format!("BigDataViewer XML: {reason}"));
        let spim = xml::read(&xml_path).map_err(fail)?;
        if is_h5 && std::fs::canonicalize(&spim.hdf5).ok() != std::fs::canonicalize(path).ok() {
            return Err(fail(format!(
                "it names {} as its HDF5 file, not {}",
                spim.hdf5.display(),
                path.display()
            )));
        }
        let notes = vec![format!(
            "BigDataViewer dataset {}: {} view setup(s), {} time point(s)",
            xml_path.display(),
            spim.setups.len(),
            spim.timepoints.len()
        )];
        return Ok(Dataset {
            described_by: xml_path.clone(),
            h5_path: spim.hdf5,
            setups: spim.setups,
            timepoints: spim.timepoints,
            registrations: spim.registrations,
            notes,
        });
    }
    // The HDF5 file alone: its groups say which setups and time points.
    let h5 = h5::open(path)?;
    let groups = h5.file.root().groups().unwrap_or_default();
    let numbered = |prefix: char, digits: usize| {
        let mut v: Vec<usize> = groups
            .iter()
            .filter(|g| g.len() == digits + 1 && g.starts_with(prefix))
            .filter_map(|g| g[1..].parse().ok())
            .collect();
        v.sort();
        v
    };
    let setups: Vec<xml::Setup> = numbered('s', 2)
        .into_iter()
        .map(|id| xml::Setup {
            id,
            name: String::new(),
            voxel: None,
        })
        .collect();
    Ok(Dataset {
        described_by: path.to_path_buf(),
        h5_path: path.to_path_buf(),
        setups,
        timepoints: numbered('t', 5),
        registrations: Default::default(),
        notes: vec![format!(
            "BigDataViewer HDF5 without its XML (no {} beside it): voxel size and registration unknown, spacing 1",
            path.with_extension("xml").display()
        )],
    })
}

/// The level-0 grid of a view: spacing, origin and unit (see the module
/// docs), with a note.
fn grid(
    path: &Path,
    setup: &xml::Setup,
    registration: Option<&[[f64; 4]; 3]>,
    notes: &mut Vec<String>,
) -> Result<(DVec3, DVec3, Option<String>), IoError> {
    let voxel = setup.voxel.as_ref();
    let Some(a) = registration else {
        return Ok(match voxel {
            Some((size, unit)) => (DVec3::from(*size), DVec3::ZERO, Some(unit.clone())),
            None => (DVec3::ONE, DVec3::ZERO, None),
        });
    };
    let diagonal = (0..3).all(|r| (0..3).all(|c| r == c || a[r][c].abs() < 1e-9));
    let scale = DVec3::new(a[0][0], a[1][1], a[2][2]);
    if !diagonal || scale.min_element() <= 0.0 {
        return Err(IoError::invalid(
            path,
            format!(
                "BigDataViewer view setup {}: its registration {a:?} rotates, shears or mirrors the view: registered views are not read yet",
                setup.id
            ),
        ));
    }
    let translation = DVec3::new(a[0][3], a[1][3], a[2][3]);
    if let Some((size, unit)) = voxel {
        let k = DVec3::from(*size) / scale;
        if (k - DVec3::splat(k.x)).abs().max_element() <= 1e-6 * k.x {
            notes.push(format!(
                "world from the registration in {unit}: voxelSize {} {} {} {unit}",
                size[0], size[1], size[2]
            ));
            return Ok((DVec3::from(*size), translation * k.x, Some(unit.clone())));
        }
        notes.push(format!(
            "voxelSize {size:?} is not proportional to the registration's scaling {scale}: BigDataViewer's world units used, unit unknown"
        ));
    }
    Ok((scale, translation, None))
}

/// Opens the view `opts` picks (see the module docs): the dataset
/// placed, and the map of its stored values where BigDataViewer reads
/// int16 as unsigned.
fn open(path: &Path, opts: &ReadOptions) -> Result<(Opened, Option<RealValue>), IoError> {
    let mut d = dataset(path)?;
    let volumes = Volumes::new(d.timepoints.len(), d.setups.len());
    let picked = volumes.pick(
        path,
        opts,
        AxisNames {
            holder: "the BigDataViewer dataset",
            time: "its time points",
            channel: "its view setups",
        },
    )?;
    let setup = d.setups[picked.channel].clone();
    let t = d.timepoints[picked.time_point];
    let h5 = h5::open(&d.h5_path)?;
    let fail = |reason: String| IoError::invalid(&d.h5_path, format!("BigDataViewer: {reason}"));
    let s = format!("s{:02}", setup.id);
    let factors = h5
        .file
        .dataset(&format!("{s}/resolutions"))
        .map_err(|e| fail(format!("no {s}/resolutions ({e})")))
        .and_then(|r| read_small(&r, 3 * 64).map_err(|e| fail(format!("{s}/resolutions: {e}"))))?;
    if factors.is_empty()
        || factors.len() % 3 != 0
        || factors.iter().any(|f| f.is_nan() || *f < 1.0)
    {
        return Err(fail(format!(
            "{s}/resolutions {factors:?} are not factors ≥ 1, three a level"
        )));
    }
    let chunks = h5
        .file
        .dataset(&format!("{s}/subdivisions"))
        .ok()
        .and_then(|r| read_small(&r, 3 * 64).ok());
    let (spacing0, origin0, unit) = grid(
        &d.described_by,
        &setup,
        d.registrations.get(&(t, setup.id)),
        &mut d.notes,
    )?;
    let mut levels = Vec::new();
    for (l, f) in factors.chunks_exact(3).enumerate() {
        let f = DVec3::new(f[0], f[1], f[2]);
        let name = format!("t{t:05}/{s}/{l}/cells");
        let Ok(ds) = h5.file.dataset(&name) else {
            return Err(fail(format!(
                "no dataset {name} for level {l} of {s}/resolutions"
            )));
        };
        let shape = h5::shape(&ds).map_err(|e| fail(format!("{name}: {e}")))?;
        if shape.len() != 3 {
            return Err(fail(format!("{name} has shape {shape:?}, not (z, y, x)")));
        }
        let sample = numeric_type(&ds).map_err(|e| fail(format!("{name}: {e}")))?;
        let bytes = if sample.name.starts_with("int16") {
            4
        } else {
            sample.size
        } as u64;
        levels.push(LevelInfo {
            path: name,
            shape: shape.iter().map(|&n| n as u64).collect(),
            dims: [shape[2], shape[1], shape[0]],
            spacing: (spacing0 * f).to_array(),
            origin: (origin0 + (f - DVec3::ONE) * 0.5 * spacing0).to_array(),
            chunk_shape: chunks.as_ref().and_then(|c| {
                let c = c.get(3 * l..3 * l + 3)?;
                Some(vec![c[2] as u64, c[1] as u64, c[0] as u64])
            }),
            shard_shape: None,
            codecs: "HDF5 chunks".into(),
            dir: d.h5_path.clone(),
            bytes_stored: None,
            bytes_in_memory: shape.iter().product::<usize>() as u64 * bytes,
        });
    }
    let level = opts.level.unwrap_or(0);
    let chosen = levels.get(level).ok_or_else(|| {
        fail(format!(
            "level {level} is out of range: the view has {} level(s), 0 to {}",
            levels.len(),
            levels.len() - 1
        ))
    })?;
    let name = format!("/{}", chosen.path);
    let dataset = h5.file.dataset(&name).map_err(|e| fail(e.to_string()))?;
    let sample = numeric_type(&dataset).map_err(|e| fail(format!("{name}: {e}")))?;
    h5::check_filters(&dataset).map_err(|e| fail(format!("{name}: {e}")))?;
    let shape: Vec<usize> = chosen.shape.iter().map(|&n| n as usize).collect();
    let roles = [Role::Z, Role::Y, Role::X];
    let placement = Placement::new(&shape, &roles, 0).map_err(|_| fail("no volume".into()))?;
    let signed16 = sample.name.starts_with("int16");
    let real: Option<RealValue> =
        signed16.then(|| Arc::new(|v: f64| if v < 0.0 { v + 65536.0 } else { v }) as RealValue);

    let mut info = FileInfo::new(sample.name.clone());
    info.set_volumes(volumes, picked);
    info.header = vec![
        ("HDF5 file".into(), d.h5_path.display().to_string()),
        (
            "dataset".into(),
            format!("{name} {shape:?} {}", sample.name),
        ),
        (
            "view setup".into(),
            format!("{} {}", setup.id, setup.name).trim().to_string(),
        ),
        ("time point".into(), t.to_string()),
    ];
    info.notes.append(&mut d.notes);
    info.notes.push(format!(
        "view setup {} (channel {} of {}), time point {t} ({} of {}), level {level} of {} (factors {:?})",
        setup.id,
        picked.channel,
        d.setups.len(),
        picked.time_point,
        d.timepoints.len(),
        levels.len(),
        &factors[3 * level..3 * level + 3]
    ));
    if signed16 {
        info.notes.push(
            "int16 samples read as unsigned 16-bit, as BigDataViewer reads them (kept as f32)"
                .into(),
        );
    }
    info.length_unit = unit.filter(|u| !u.is_empty());
    let spacing = DVec3::from(chosen.spacing);
    let origin = DVec3::from(chosen.origin);
    let dims = placement.dims;
    info.levels = levels;
    info.level = level;
    Ok((
        Opened {
            file_path: d.h5_path.clone(),
            h5,
            name,
            dataset,
            sample,
            shape,
            placement,
            dims,
            info,
            spacing,
            origin,
        },
        real,
    ))
}
