#!/bin/sh
# Builds the fuzzing corpora (fuzz/corpus/<target>/, not committed) from the
# readers' test fixtures (crates/io/tests/fixtures/) and the committed
# hand-made seeds (fuzz/seeds/<target>/; dx, xsf and plt: files written by
# crates/io/tests/chem_grids/write_files.py, npz and gipl: by
# crates/io/tests/npz/ and gipl/write_files.py; mrtrix: after its documented layout). Targets whose reader takes
# --frame/--array read a control byte before the file (see fuzz/src/lib.rs):
# fixtures get 0x00 (defaults) and, where they hold several volumes or need
# a detached header's name, the byte that picks that.
# Usage: fuzz/seed.sh [target...]   (default: every target)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
fix="$here/../crates/io/tests/fixtures"
corpus="$here/corpus"

# add TARGET CONTROL FILE...: FILE with a control byte (hex, or "none") in front.
add() {
    target=$1 control=$2
    shift 2
    mkdir -p "$corpus/$target"
    for f in "$@"; do
        [ -f "$f" ] || continue
        name="$(basename "$(dirname "$f")")_$(basename "$f")_$control"
        if [ "$control" = none ]; then
            cp "$f" "$corpus/$target/$name"
        else
            { printf "\\$(printf '%03o' "0x$control")"; cat "$f"; } >"$corpus/$target/$name"
        fi
    done
}

targets=${*:-"raw npy nrrd metaimage nifti vtk vti dicom dicomdir tiff cube mrc chgcar hdf5 minc zarr netcdf fits mgh dx xsf plt npz gipl mrtrix"}
for t in $targets; do
    case $t in
    raw) add raw none "$here"/seeds/raw/* ;;
    dx | plt | gipl | mrtrix) add $t 00 "$here"/seeds/$t/* ;;
    npz)
        add npz 00 "$here"/seeds/npz/*
        add npz 20 "$here"/seeds/npz/named.npz
        ;;
    xsf)
        add xsf 00 "$here"/seeds/xsf/*
        add xsf 02 "$here"/seeds/xsf/fermi.bxsf
        ;;
    npy) add npy none "$fix"/*.npy ;;
    mrc) add mrc none "$fix"/mrc/* ;;
    nrrd)
        add nrrd 00 "$fix"/nrrd/*.nrrd
        add nrrd 08 "$fix"/nrrd/*.nhdr
        add nrrd 02 "$fix"/nrrd/time4d.nrrd "$fix"/nrrd/vector4d.nrrd
        ;;
    metaimage)
        add metaimage 00 "$fix"/metaimage/*.mha
        add metaimage 08 "$fix"/metaimage/*.mhd
        add metaimage 02 "$fix"/metaimage/series4d.mha
        ;;
    nifti)
        add nifti 00 "$fix"/nifti/*.nii "$fix"/nifti/*.nii.gz
        add nifti 08 "$fix"/nifti/pair.hdr
        add nifti 02 "$fix"/nifti/frames4d.nii.gz "$fix"/nifti/nifti2_frames4d.nii
        add nifti 02 "$fix"/nifti/vector5d.nii "$fix"/nifti/vector5d_t2.nii.gz
        add nifti 08 "$fix"/analyze/*.hdr
        ;;
    mgh)
        add mgh 00 "$fix"/mgh/*.mgh
        add mgh 08 "$fix"/mgh/*.mgz
        add mgh 09 "$fix"/mgh/f32.mgz "$fix"/mgh/u8.mgz
        ;;
    vtk)
        add vtk 00 "$fix"/vtk/*.vtk
        add vtk 10 "$fix"/vtk/legacy_multi_*.vtk
        add vtk 40 "$fix"/vtk/legacy_multi_*.vtk "$fix"/vtk/legacy_cells_only.vtk
        ;;
    vti)
        add vti 00 "$fix"/vtk/*.vti
        add vti 10 "$fix"/vtk/vti_extent.vti
        add vti 40 "$fix"/vtk/vti_direction.vti
        add vti 70 "$fix"/vtk/vti_binary_zlib.vti
        add vti a0 "$fix"/vtk/vti_types.vti
        ;;
    dicom)
        add dicom 00 "$fix"/dicom/*.dcm "$fix"/dicom/*/*.dcm "$fix"/dicom/ct/IM*
        add dicom 08 "$fix"/dicom/single.dcm "$fix"/dicom/enhanced_ct.dcm
        add dicom 02 "$fix"/dicom/enhanced_4d.dcm
        add dicom 08 "$fix"/dicom/jpeg_split.dcm "$fix"/dicom/j2k_split.dcm "$fix"/dicom/jpegls_frames.dcm
        ;;
    dicomdir)
        add dicomdir 00 "$fix"/dicom/cd/DICOMDIR
        add dicomdir 01 "$fix"/dicom/cd/DICOMDIR
        add dicomdir 06 "$fix"/dicom/cd/DICOMDIR
        ;;
    tiff)
        add tiff 00 "$fix"/tiff/*.tif
        add tiff 02 "$fix"/tiff/imagej_hyper.tif
        ;;
    cube)
        add cube 00 "$fix"/cube/*.cube
        add cube 02 "$fix"/cube/orbitals_angstrom.cube
        ;;
    chgcar)
        add chgcar 00 "$fix"/chgcar/*
        add chgcar 02 "$fix"/chgcar/CHGCAR_spin
        ;;
    hdf5)
        # The control byte's high nibble picks the dataset (fuzz_targets/hdf5.rs).
        add hdf5 00 "$fix"/hdf5/one.h5
        for c in 10 20 30 40 50 60 70 72 80 90; do add hdf5 $c "$fix"/hdf5/many.h5; done
        # HDF5 2.0's chunk indexes (through hdf5-reader), whole and box by box.
        for c in 10 18 30 38 60 68 70 79; do add hdf5 $c "$fix"/hdf5/latest.h5; done
        ;;
    minc)
        add minc 00 "$fix"/minc/*.mnc
        add minc 02 "$fix"/minc/series_u8.mnc "$fix"/minc/series_minc1.mnc
        ;;
    netcdf)
        # Control: frame in bits 0-2, array in bits 4-6 (fuzz_targets/netcdf.rs).
        add netcdf 00 "$fix"/netcdf/*.nc "$fix"/minc/*minc1.mnc
        add netcdf 12 "$fix"/netcdf/classic.nc "$fix"/netcdf/data64.nc
        add netcdf 22 "$fix"/netcdf/offset64.nc
        add netcdf 02 "$fix"/netcdf/packed.nc
        ;;
    # Only the committed seeds (make_zarr_seeds.py): a store is two files
    # packed into one input (fuzz_targets/zarr.rs).
    zarr) ;;
    fits)
        add fits 00 "$fix"/fits/*.fits "$fix"/fits/*.fits.gz
        add fits 03 "$fix"/fits/multi.fits
        add fits 22 "$fix"/fits/multi.fits
        ;;
    *) echo "seed.sh: unknown target $t" >&2; exit 1 ;;
    esac
    [ -d "$here/seeds/$t" ] && [ "$t" != raw ] && add "$t" none "$here"/seeds/"$t"/*
    echo "$t: $(ls "$corpus/$t" | wc -l) seeds"
done
