#!/usr/bin/env python3
"""Makes an OME-Zarr 0.5 pyramid far larger than the disk, honestly: an
N x N x N tiling of a pyramid volray wrote (`volray convert`), whose shard
files are hard links to the tile's own.

Why it is the volume it says it is: level k of the tiling is the tiling of
the tile's level k, as long as the tile's side is a multiple of 2^k (a
block average never straddles two copies), and each shard of the tiled
level holds exactly the samples of one shard of the tile's level when the
tile's level is a whole number of shards (its shard shape divides its
shape). So level k of the big store lists the same zarr.json as the
tile's level k but with a shape N times larger, and shard (i, j, l) is a
hard link to the tile's shard (i mod n, j mod n, l mod n). The levels
coarser than the tile's coarsest are made by `volray convert` from the
tiling of that coarsest level (small: N times the tile's coarsest side).
No sample is synthesised by this script beyond that copy; every byte the
renderer reads comes from a file volray wrote, through the ordinary Zarr
reader.

A 1024³ tile at N = 16 gives 16384³ u16: 8 TiB of samples at level 0
(9.1 TiB in all) on a few GiB of disk. ext4 allows 65 000 links a file:
level 0 of that store links each of the tile's 64 shards 4096 times.

Usage: make_tiled_pyramid.py TILE.ome.zarr N OUT.ome.zarr VOLRAY
(VOLRAY: the volray binary, for the coarse levels). Needs numpy and zarr
(target/pyenv has them).
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np
import zarr


def level_meta(store, path):
    with open(os.path.join(store, path, "zarr.json")) as f:
        return json.load(f)


def shard_shape(meta):
    codecs = meta["codecs"]
    if codecs and codecs[0]["name"] == "sharding_indexed":
        return meta["chunk_grid"]["configuration"]["chunk_shape"]
    return meta["chunk_grid"]["configuration"]["chunk_shape"]


def link_level(tile, out, k, path, n):
    meta = level_meta(tile, path)
    shape = meta["shape"]
    shard = shard_shape(meta)
    if any(s % c for s, c in zip(shape, shard)):
        return False
    grid = [s // c for s, c in zip(shape, shard)]
    big = dict(meta)
    big["shape"] = [s * n for s in shape]
    dst = os.path.join(out, str(k))
    os.makedirs(dst)
    with open(os.path.join(dst, "zarr.json"), "w") as f:
        json.dump(big, f, indent=2)
    links = 0
    for z in range(grid[0] * n):
        for y in range(grid[1] * n):
            d = os.path.join(dst, "c", str(z), str(y))
            os.makedirs(d)
            for x in range(grid[2] * n):
                src = os.path.join(tile, path, "c", str(z % grid[0]), str(y % grid[1]), str(x % grid[2]))
                if os.path.exists(src):  # a missing shard is the fill value in both
                    os.link(src, os.path.join(d, str(x)))
                    links += 1
    print(f"level {k}: {big['shape']} linked, {links} shard files", flush=True)
    return True


def main():
    tile, n, out, volray = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
    if os.path.exists(out):
        sys.exit(f"{out} exists")
    with open(os.path.join(tile, "zarr.json")) as f:
        group = json.load(f)
    ms = group["attributes"]["ome"]["multiscales"][0]
    datasets = ms["datasets"]
    os.makedirs(out)
    levels = []
    for k, ds in enumerate(datasets):
        if not link_level(tile, out, k, ds["path"], n):
            break
        levels.append(ds)
    # The coarser levels: volray convert of the tiling of the coarsest linked level.
    last = len(levels) - 1
    coarsest = zarr.open_array(os.path.join(tile, datasets[last]["path"]), mode="r")[...]
    tiled = np.tile(coarsest, (n, n, n))
    dims = ",".join(str(s) for s in tiled.shape[::-1])
    with tempfile.TemporaryDirectory(dir=os.path.dirname(os.path.abspath(out))) as tmp:
        raw = os.path.join(tmp, "coarse.raw")
        tiled.astype("<u2").tofile(raw)
        del tiled
        small = os.path.join(tmp, "coarse.ome.zarr")
        subprocess.run([volray, "convert", raw, "--dims", dims, "--dtype", "u16", "-o", small], check=True)
        with open(os.path.join(small, "zarr.json")) as f:
            sms = json.load(f)["attributes"]["ome"]["multiscales"][0]["datasets"]
        base = levels[last]["coordinateTransformations"][0]["scale"]
        for j, ds in enumerate(sms[1:], start=1):
            k = last + j
            shutil.move(os.path.join(small, ds["path"]), os.path.join(out, str(k)))
            f = 2**j
            scale = [b * f for b in base]
            # Level k's voxel 0 is the mean of the finest level's first
            # 2^k voxels: centred at (2^k − 1)/2 finest voxels.
            fine = datasets[0]["coordinateTransformations"][0]["scale"]
            translation = [(s / q - 1) / 2 * q for s, q in zip(scale, fine)]
            levels.append(
                {
                    "path": str(k),
                    "coordinateTransformations": [
                        {"type": "scale", "scale": scale},
                        {"type": "translation", "translation": translation},
                    ],
                }
            )
            print(f"level {k}: converted", flush=True)
    for k, ds in enumerate(levels):
        ds["path"] = str(k)
    ms = dict(ms)
    ms["datasets"] = levels
    ms["name"] = f"{ms.get('name', 'tile')} tiled {n}x{n}x{n}"
    group["attributes"]["ome"]["multiscales"] = [ms]
    with open(os.path.join(out, "zarr.json"), "w") as f:
        json.dump(group, f, indent=2)


if __name__ == "__main__":
    main()
