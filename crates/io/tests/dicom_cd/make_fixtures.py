"""Write the DICOM file-sets read by crates/io/tests/dicom_cd.rs into the
folder named on the command line, with pydicom and highdicom:

    flat/    series A: CT, SeriesNumber 3 "chest", 5 slices of 4 columns (x)
             by 3 rows (y), int16 v = x + 10*y + 100*z, RescaleIntercept
             -1000 (so values are v - 1000), PixelSpacing 0.8 (rows) x 0.6
             (columns), slices 2.5 mm apart from IPP (-10, 20, 30),
             file names shuffled
    small/   series B: MR, SeriesNumber 1 "scout", 2 slices of 4 x 3,
             uint16 v + 7, unit spacing
    cd/      series A and B through pydicom's FileSet: a DICOMDIR at the
             top, the files in PT000000/ST000000/SE00000n/IM00000n
    tree/    series A's files two folders down (tree/a/b/), a README, and
             a symbolic link tree/a/b/up -> .. (a loop)
    seg.dcm  highdicom Segmentation (BINARY) of series A, 3 segments:
             1 "left" where x = 0, 2 "block" where 1 <= x <= 2 and y >= 1
             and 1 <= z <= 3, 3 "corner" at (3, 2, 4); colours red, blue
             and (128, 64, 200); every frame kept
    seg_omitted.dcm  the same, empty frames left out (highdicom's default)
    seg_fractional.dcm  FRACTIONAL (MaximumFractionalValue 200): segment 1
             0.75 where x = 0 and 0.25 where x = 1, segment 2 1.0 at
             (3, 2, z)
"""

import os
import random
import sys

import numpy as np
import highdicom as hd
import pydicom
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.fileset import FileSet
from pydicom.sr.codedict import codes
from pydicom.uid import CTImageStorage, ExplicitVRLittleEndian, MRImageStorage

out = sys.argv[1]
ROOT = "1.2.826.0.1.3680043.10.1234"
STUDY = ROOT + ".1"


def v(z):
    x = np.arange(4)[None, :]
    y = np.arange(3)[:, None]
    return x + 10 * y + 100 * z


def slice_ds(sop, series_uid, number, description, modality, z, array, spacing, ipp, rescale):
    ds = Dataset()
    ds.file_meta = FileMetaDataset()
    ds.file_meta.MediaStorageSOPClassUID = sop
    ds.file_meta.MediaStorageSOPInstanceUID = f"{series_uid}.{z + 1}"
    ds.file_meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds.SOPClassUID = sop
    ds.SOPInstanceUID = ds.file_meta.MediaStorageSOPInstanceUID
    ds.PatientName = "Phantom^CD"
    ds.PatientID = "CD1"
    ds.PatientBirthDate = ""
    ds.PatientSex = "O"
    ds.StudyInstanceUID = STUDY
    ds.StudyID = "1"
    ds.StudyDate = "20260101"
    ds.StudyTime = "120000"
    ds.AccessionNumber = ""
    ds.ReferringPhysicianName = ""
    ds.SeriesInstanceUID = series_uid
    ds.SeriesNumber = number
    ds.SeriesDescription = description
    ds.Modality = modality
    ds.InstanceNumber = z + 1
    ds.FrameOfReferenceUID = ROOT + ".9"
    ds.PositionReferenceIndicator = ""
    ds.Manufacturer = "volray tests"
    ds.ImagePositionPatient = [ipp[0], ipp[1], ipp[2] + spacing[2] * z]
    ds.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
    ds.PixelSpacing = [spacing[1], spacing[0]]
    ds.SliceThickness = spacing[2]
    ds.SamplesPerPixel = 1
    ds.PhotometricInterpretation = "MONOCHROME2"
    ds.Rows, ds.Columns = array.shape
    ds.BitsAllocated = 16
    ds.BitsStored = 16
    ds.HighBit = 15
    signed = array.dtype == np.int16
    ds.PixelRepresentation = 1 if signed else 0
    if rescale is not None:
        ds.RescaleIntercept = rescale
        ds.RescaleSlope = 1
        ds.RescaleType = "HU"
    ds.PixelData = array.tobytes()
    ds.is_little_endian = True
    ds.is_implicit_VR = False
    return ds


series_a = ROOT + ".2"
series_b = ROOT + ".3"
a = [
    slice_ds(CTImageStorage, series_a, 3, "chest", "CT", z, v(z).astype(np.int16),
             (0.6, 0.8, 2.5), (-10.0, 20.0, 30.0), -1000)
    for z in range(5)
]
b = [
    slice_ds(MRImageStorage, series_b, 1, "scout", "MR", z, (v(z) + 7).astype(np.uint16),
             (1.0, 1.0, 1.0), (0.0, 0.0, 0.0), None)
    for z in range(2)
]

os.makedirs(f"{out}/flat")
names = [f"slice{n}.dcm" for n in range(5)]
random.Random(3).shuffle(names)
for ds, name in zip(a, names):
    ds.save_as(f"{out}/flat/{name}", enforce_file_format=True)
os.makedirs(f"{out}/small")
for z, ds in enumerate(b):
    ds.save_as(f"{out}/small/s{z}.dcm", enforce_file_format=True)

fs = FileSet()
for ds in b + a:
    fs.add(ds)
fs.write(f"{out}/cd")

os.makedirs(f"{out}/tree/a/b")
for ds, name in zip(a, names):
    ds.save_as(f"{out}/tree/a/b/{name}", enforce_file_format=True)
with open(f"{out}/tree/README.txt", "w") as f:
    f.write("not DICOM\n")
os.symlink("..", f"{out}/tree/a/b/up")

# The segmentation: (frames = slices, rows, columns, segments).
mask = np.zeros((5, 3, 4, 3), dtype=bool)
mask[:, :, 0, 0] = True
mask[1:4, 1:, 1:3, 1] = True
mask[4, 2, 3, 2] = True
colours = [(255, 0, 0), (0, 0, 255), (128, 64, 200)]
labels = ["left", "block", "corner"]
descriptions = [
    hd.seg.SegmentDescription(
        segment_number=n + 1,
        segment_label=labels[n],
        segmented_property_category=codes.SCT.Tissue,
        segmented_property_type=codes.SCT.Tissue,
        algorithm_type=hd.seg.SegmentAlgorithmTypeValues.MANUAL,
        display_color=hd.color.CIELabColor.from_rgb(*colours[n]),
    )
    for n in range(3)
]
for name, omit in [("seg.dcm", False), ("seg_omitted.dcm", True)]:
    seg = hd.seg.Segmentation(
        source_images=a,
        pixel_array=mask,
        segmentation_type=hd.seg.SegmentationTypeValues.BINARY,
        segment_descriptions=descriptions,
        series_instance_uid=ROOT + ".4",
        series_number=10,
        sop_instance_uid=ROOT + ".4.1",
        instance_number=1,
        manufacturer="volray tests",
        manufacturer_model_name="fixtures",
        software_versions="1",
        device_serial_number="1",
        omit_empty_frames=omit,
    )
    seg.save_as(f"{out}/{name}")

# FRACTIONAL: segment 1 at 0.75 where x = 0 and 0.25 where x = 1 (below
# one half: not in the segment), segment 2 at 1.0 at (3, 2, z).
fraction = np.zeros((5, 3, 4, 2), dtype=np.float32)
fraction[:, :, 0, 0] = 0.75
fraction[:, :, 1, 0] = 0.25
fraction[:, 2, 3, 1] = 1.0
seg = hd.seg.Segmentation(
    source_images=a,
    pixel_array=fraction,
    segmentation_type=hd.seg.SegmentationTypeValues.FRACTIONAL,
    segment_descriptions=descriptions[:2],
    series_instance_uid=ROOT + ".5",
    series_number=11,
    sop_instance_uid=ROOT + ".5.1",
    instance_number=1,
    manufacturer="volray tests",
    manufacturer_model_name="fixtures",
    software_versions="1",
    device_serial_number="1",
    max_fractional_value=200,
)
seg.save_as(f"{out}/seg_fractional.dcm")
