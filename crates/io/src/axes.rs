//! One model of the axes beside space, for every reader: a file holds
//! `T` time points of `C` channels, each a volume of x, y, z: OME's
//! TCZYX, time and channel kept apart ([`Volumes`]).
//!
//! [`ReadOptions::frame`] picks the time point and
//! [`ReadOptions::channel`] the channel, in every format; a reader that
//! knows both axes asks [`Volumes::pick`] which volume they name (each
//! checked against its extent, refused in one line naming the file) and
//! finds it where its file keeps it: an ImageJ hyperstack's pages (channel
//! fastest), an OME-TIFF's `DimensionOrder`, an HDF5 dataset's named
//! axes in their order, a 5-D NIfTI's blocks (time fastest, `dim[4]`,
//! then the components of `dim[5]`), a Zarr array's `t` and `c`.
//! [`FileInfo::set_volumes`] records what the file holds and what was
//! read, so that `volray info`, `--channels` and `--frames` count the
//! same axes.
//!
//! The volumes are numbered `t·C + c` (channel fastest, as in OME's
//! TCZYX): [`FileInfo::frames`] counts them (`T·C`) and
//! [`FileInfo::frame`] is the number of the one read. A reader that
//! knows of no channel axis (a cube file's orbitals, a DICOM directory's
//! series, NetCDF time) numbers its volumes along time, one channel;
//! [`read`](crate::read) fills in that model for it
//! ([`FileInfo::fill_volumes`]).

use std::path::Path;

use crate::{FileInfo, IoError, ReadOptions};

/// How many time points and channels a file holds: `time_points ·
/// channels` volumes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Volumes {
    pub time_points: usize,
    pub channels: usize,
}

/// One volume of a file: its time point and channel, from 0.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Picked {
    pub time_point: usize,
    pub channel: usize,
}

/// Where a file keeps its time and channel axes, for messages: who holds
/// them (`the file`, `the stack`, `HDF5 dataset "/a"`) and what each axis
/// is called there (`dim[4]`, `axis "c"`).
#[derive(Debug, Clone, Copy)]
pub struct AxisNames<'a> {
    pub holder: &'a str,
    pub time: &'a str,
    pub channel: &'a str,
}

impl Volumes {
    /// One volume: a file of one time point and one channel.
    pub const ONE: Volumes = Volumes {
        time_points: 1,
        channels: 1,
    };

    pub fn new(time_points: usize, channels: usize) -> Self {
        Volumes {
            time_points,
            channels,
        }
    }

    /// The volumes in all, `T·C` (saturating: a reader checks its
    /// extents against the file before it counts them).
    pub fn count(self) -> usize {
        self.time_points.saturating_mul(self.channels)
    }

    /// The number of volume `p`: `t·C + c`, channel fastest.
    pub fn index(self, p: Picked) -> usize {
        p.time_point * self.channels + p.channel
    }

    /// The volume numbered `index` (see [`index`](Self::index)).
    pub fn at(self, index: usize) -> Picked {
        let c = self.channels.max(1);
        Picked {
            time_point: index / c,
            channel: index % c,
        }
    }

    /// The volume `opts` asks for: time point [`ReadOptions::frame`] and
    /// channel [`ReadOptions::channel`] (0 each by default), each checked
    /// against what the file holds.
    pub fn pick(
        self,
        path: &Path,
        opts: &ReadOptions,
        names: AxisNames,
    ) -> Result<Picked, IoError> {
        let picked = Picked {
            time_point: opts.frame.unwrap_or(0),
            channel: opts.channel.unwrap_or(0),
        };
        if picked.channel >= self.channels {
            return Err(IoError::channel_out_of_range(
                path,
                picked.channel,
                self.channels_held(names),
            ));
        }
        if picked.time_point >= self.time_points {
            return Err(IoError::frame_out_of_range(
                path,
                picked.time_point,
                self.time_points_held(names),
            ));
        }
        Ok(picked)
    }

    /// `the file holds 3 channels (dim[5]), numbered from 0`.
    pub fn channels_held(self, names: AxisNames) -> String {
        let c = self.channels;
        let axis = if names.channel.is_empty() {
            String::new()
        } else {
            format!(" ({})", names.channel)
        };
        format!(
            "{} holds {c} channel{}{axis}, numbered from 0",
            names.holder,
            plural(c)
        )
    }

    /// `the file holds 2 volumes (dim[4]), numbered from 0` for one
    /// channel; `... 2 time points (dim[4]) of 3 channels (dim[5]) ...`
    /// for several.
    pub fn time_points_held(self, names: AxisNames) -> String {
        let (t, c) = (self.time_points, self.channels);
        let time = if names.time.is_empty() {
            String::new()
        } else {
            format!(" ({})", names.time)
        };
        if c > 1 {
            let channel = if names.channel.is_empty() {
                String::new()
            } else {
                format!(" ({})", names.channel)
            };
            format!(
                "{} holds {t} time point{}{time} of {c} channels{channel}, numbered from 0",
                names.holder,
                plural(t)
            )
        } else {
            format!(
                "{} holds {t} volume{}{time}, numbered from 0",
                names.holder,
                plural(t)
            )
        }
    }
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

impl FileInfo {
    /// Records that the file holds `volumes` and that `picked` was read:
    /// [`time_points`](Self::time_points), [`channels`](Self::channels),
    /// [`time_point`](Self::time_point), [`channel`](Self::channel), and
    /// the volumes' count and number ([`frames`](Self::frames),
    /// [`frame`](Self::frame), `t·C + c`).
    pub fn set_volumes(&mut self, volumes: Volumes, picked: Picked) {
        self.time_points = volumes.time_points;
        self.channels = volumes.channels;
        self.time_point = picked.time_point;
        self.channel = picked.channel;
        self.frames = volumes.count();
        self.frame = volumes.index(picked);
    }

    /// What the file holds, as [`set_volumes`](Self::set_volumes) set it.
    pub fn volumes(&self) -> Volumes {
        Volumes::new(self.time_points, self.channels)
    }

    /// The model for a reader that counted its volumes
    /// ([`frames`](Self::frames), [`frame`](Self::frame)) without
    /// [`set_volumes`](Self::set_volumes): its volumes are time points of
    /// one channel.
    pub fn fill_volumes(&mut self) {
        let set = self.time_points.max(1) * self.channels.max(1) == self.frames.max(1)
            && self.time_points > 0
            && self.channels > 0;
        if !set {
            let frames = self.frames.max(1);
            let frame = self.frame;
            self.set_volumes(
                Volumes::new(frames, 1),
                Picked {
                    time_point: frame,
                    channel: 0,
                },
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const NAMES: AxisNames<'static> = AxisNames {
        holder: "the file",
        time: "dim[4]",
        channel: "dim[5]",
    };

    fn opts(frame: Option<usize>, channel: Option<usize>) -> ReadOptions {
        ReadOptions {
            frame,
            channel,
            ..ReadOptions::default()
        }
    }

    #[test]
    fn volumes_are_numbered_channel_fastest_and_back() {
        let v = Volumes::new(2, 3);
        assert_eq!(v.count(), 6);
        let mut seen = Vec::new();
        for t in 0..2 {
            for c in 0..3 {
                let p = Picked {
                    time_point: t,
                    channel: c,
                };
                assert_eq!(v.at(v.index(p)), p);
                seen.push(v.index(p));
            }
        }
        assert_eq!(seen, (0..6).collect::<Vec<_>>());
    }

    #[test]
    fn the_frame_picks_the_time_point_and_the_channel_the_channel() {
        let v = Volumes::new(2, 3);
        let p = v.pick(Path::new("a.nii"), &opts(Some(1), Some(2)), NAMES);
        assert_eq!(
            p.unwrap(),
            Picked {
                time_point: 1,
                channel: 2
            }
        );
        assert_eq!(
            v.pick(Path::new("a.nii"), &opts(None, None), NAMES)
                .unwrap(),
            Picked::default()
        );
        let err = v
            .pick(Path::new("a.nii"), &opts(Some(2), None), NAMES)
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "a.nii: frame 2 is out of range: the file holds 2 time points (dim[4]) of 3 channels (dim[5]), numbered from 0"
        );
        let err = v
            .pick(Path::new("a.nii"), &opts(None, Some(3)), NAMES)
            .unwrap_err();
        assert!(matches!(err, IoError::ChannelOutOfRange { channel: 3, .. }));
        assert_eq!(
            err.to_string(),
            "a.nii: channel 3 is out of range: the file holds 3 channels (dim[5]), numbered from 0"
        );
        let one = Volumes::new(2, 1);
        let err = one
            .pick(Path::new("a.nii"), &opts(Some(5), None), NAMES)
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "a.nii: frame 5 is out of range: the file holds 2 volumes (dim[4]), numbered from 0"
        );
    }

    #[test]
    fn a_reader_counting_frames_alone_gets_time_points_of_one_channel() {
        let mut info = FileInfo::new("u8");
        info.frames = 4;
        info.frame = 3;
        info.fill_volumes();
        assert_eq!(info.volumes(), Volumes::new(4, 1));
        assert_eq!((info.time_point, info.channel), (3, 0));
        let mut info = FileInfo::new("u8");
        info.set_volumes(
            Volumes::new(2, 3),
            Picked {
                time_point: 1,
                channel: 1,
            },
        );
        info.fill_volumes();
        assert_eq!((info.frames, info.frame), (6, 4));
        assert_eq!(info.volumes(), Volumes::new(2, 3));
    }
}
