//! The camera: the image's size in pixels, where the eye stands and looks
//! (`--view`, `--look-at`, `--up`), the projection and its framing
//! (`--perspective`, `--zoom`, `--azimuth`, `--elevation`), and the part
//! of the world it sees (`--clip`, `--crop`).
//!
//! `--size` is here rather than with the output file because it is the
//! camera's film: the window's aspect ratio and the rays' spacing follow
//! from it (volray-core checks it with the camera), and `bench`, which
//! writes no image, takes it too.

use super::parse::{
    parse_angle, parse_clip, parse_crop, parse_direction, parse_fov, parse_size, parse_vec3,
    parse_zoom,
};
use clap::Args;

/// The image size without `--size`.
pub const DEFAULT_SIZE: (usize, usize) = (480, 480);

impl CameraArgs {
    /// `--size`, else `DEFAULT_SIZE`.
    pub fn size(&self) -> (usize, usize) {
        self.size.unwrap_or(DEFAULT_SIZE)
    }
}

/// What the picture frames, and at what resolution.
#[derive(Debug, Args)]
pub struct CameraArgs {
    /// Image size: W (square) or WxH, in pixels (`volray view` without
    /// it: the size of the page's window) [default: 480].
    #[arg(long, value_name = "W|WxH", value_parser = parse_size, allow_hyphen_values = true)]
    pub size: Option<(usize, usize)>,

    /// View point, world coordinates [default: on the +x axis through the
    /// view reference, looking along −x, as in the paper's Fig. 1a].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub view: Option<[f64; 3]>,

    /// View reference (the point looked at, the image centre) [default: the
    /// centre of the volume].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub look_at: Option<[f64; 3]>,

    /// Up direction.
    #[arg(long, value_name = "X,Y,Z", default_value = "0,0,1", value_parser = parse_direction, allow_hyphen_values = true)]
    pub up: [f64; 3],

    /// Perspective projection with this vertical field of view in degrees
    /// (0 < FOV < 180) [default: orthographic]. Without --view the eye
    /// stands where the volume's bounding sphere just fills the view.
    #[arg(long, value_name = "FOV", value_parser = parse_fov, allow_hyphen_values = true, help_heading = "Camera")]
    pub perspective: Option<f64>,

    /// Magnification about the image centre, > 0: 2 shows everything twice
    /// as large (as VTK's Zoom).
    #[arg(long, value_name = "Z", default_value_t = 1.0, value_parser = parse_zoom, allow_hyphen_values = true, help_heading = "Camera")]
    pub zoom: f64,

    /// Degrees the view point orbits about the up vector through the view
    /// reference (VTK's Azimuth: 90 takes the default eye from +x to +y).
    #[arg(long, value_name = "DEG", default_value_t = 0.0, value_parser = parse_angle, allow_hyphen_values = true, help_heading = "Camera")]
    pub azimuth: f64,

    /// Degrees the view point then rises about the screen's horizontal
    /// axis (VTK's Elevation: 90 looks down the up vector).
    #[arg(long, value_name = "DEG", default_value_t = 0.0, value_parser = parse_angle, allow_hyphen_values = true, help_heading = "Camera")]
    pub elevation: f64,

    /// A clip plane through the world point X,Y,Z with normal NX,NY,NZ:
    /// keeps the side the normal points to. Repeatable: what every plane
    /// keeps is rendered.
    #[arg(long, value_name = "X,Y,Z,NX,NY,NZ", value_parser = parse_clip, allow_hyphen_values = true, help_heading = "Camera")]
    pub clip: Vec<([f64; 3], [f64; 3])>,

    /// Render only the world box X0..X1, Y0..Y1, Z0..Z1 (VTK's cropping
    /// region planes, in world coordinates rather than voxels).
    #[arg(long, value_name = "X0,X1,Y0,Y1,Z0,Z1", value_parser = parse_crop, allow_hyphen_values = true, help_heading = "Camera")]
    pub crop: Option<([f64; 3], [f64; 3])>,
}
