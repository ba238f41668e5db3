//! Typed flag values that are not named choices (those are
//! [`crate::choice`]): picture sizes, views, cameras, voxel sizes and memory sizes. Each
//! parses in one function that clap calls (`value_parser`), so a command
//! receives the value checked, and each has its tests here.

use glam::Vec3;
use topovox::render::raycast::View;

/// Largest picture side and pixel count accepted.
const MAX_SIDE: u32 = 16_384;
const MAX_PIXELS: u64 = 64 << 20;

/// A picture's size in pixels (`--size WIDTHxHEIGHT`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Size {
    /// Pixels across.
    pub width: u32,
    /// Pixels down.
    pub height: u32,
}

/// `WIDTHxHEIGHT` within the picture limits.
pub fn size(text: &str) -> Result<Size, String> {
    let parsed: Option<(u32, u32)> = text.split_once(['x', 'X']).and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)));
    let Some((width, height)) = parsed else { return Err("--size takes WIDTHxHEIGHT in pixels, e.g. 1024x768".into()) };
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE || width as u64 * height as u64 > MAX_PIXELS {
        return Err(format!("--size {width}x{height}: each side must be 1..={MAX_SIDE} and the picture at most {MAX_PIXELS} pixels"));
    }
    Ok(Size { width, height })
}

/// `iso`, `x`, `y`, `z` or `AZIMUTH,ELEVATION` in degrees (`--view`).
pub fn view(text: &str) -> Result<View, String> {
    Ok(match text.trim() {
        "iso" => View::Iso,
        "x" => View::Axis(0),
        "y" => View::Axis(1),
        "z" => View::Axis(2),
        other => match numbers(other).as_deref() {
            Some([az, el]) => View::Angles(*az as f64, *el as f64),
            _ => return Err("--view takes iso, x, y, z or AZIMUTH,ELEVATION in degrees".into()),
        },
    })
}

/// A voxel size: `S` (cubes) or `SX,SY,SZ` (`--voxel-size`); the grid
/// request checks that each is positive and finite.
pub fn voxel_size(text: &str) -> Result<topovox::VoxelSize, String> {
    let n: Option<Vec<f64>> = text.split(',').map(|x| x.trim().parse::<f64>().ok()).collect();
    match n.as_deref() {
        Some(&[s]) => Ok(s.into()),
        Some(&[x, y, z]) => Ok([x, y, z].into()),
        _ => Err("--voxel-size takes S (cubes) or SX,SY,SZ (a size per axis), e.g. 0.7,0.7,2.5".into()),
    }
}

/// Comma-separated finite numbers, or `None`.
fn numbers(text: &str) -> Option<Vec<f32>> {
    text.split(',').map(|x| x.trim().parse::<f32>().ok().filter(|v| v.is_finite())).collect()
}

/// A camera as the GPU renderer, the viewer and the spray take it: eye,
/// target and vertical field of view (`--camera EX,EY,EZ,TX,TY,TZ[,FOV]`,
/// negative coordinates included; the up direction comes from `--up`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSpec {
    /// Eye position.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Vertical field of view, degrees.
    pub fov_deg: f32,
}

/// `EX,EY,EZ,TX,TY,TZ[,FOV]`.
pub fn camera(text: &str) -> Result<CameraSpec, String> {
    let Some(v) = numbers(text).filter(|v| v.len() == 6 || v.len() == 7) else {
        return Err("--camera takes EX,EY,EZ,TX,TY,TZ[,FOV]: an eye, a target and a vertical field of view in degrees".into());
    };
    let (eye, target) = (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]));
    let fov_deg = v.get(6).copied().unwrap_or(45.0);
    if !(fov_deg > 0.5 && fov_deg < 179.0) {
        return Err(format!("--camera: the field of view must be between 0.5 and 179 degrees, not {fov_deg}"));
    }
    if (eye - target).length() <= f32::EPSILON * eye.abs().max(target.abs()).max_element().max(1.0) {
        return Err("--camera: the eye and the target must differ".into());
    }
    Ok(CameraSpec { eye, target, fov_deg })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(size("1024x768"), Ok(Size { width: 1024, height: 768 }));
        assert_eq!(size(" 3 X 4 "), Ok(Size { width: 3, height: 4 }));
        for bad in ["1024", "0x5", "20000x1", "8192x8193", "axb", "-1x5"] {
            assert!(size(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn voxel_sizes() {
        assert_eq!(voxel_size("0.5"), Ok(0.5.into()));
        assert_eq!(voxel_size("0.7, 0.7,2.5"), Ok([0.7, 0.7, 2.5].into()));
        for bad in ["", "a", "1,2", "1,2,3,4", "1,,2"] {
            assert!(voxel_size(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn views() {
        assert_eq!(view("iso"), Ok(View::Iso));
        assert_eq!(view("z"), Ok(View::Axis(2)));
        assert_eq!(view("-30,15.5"), Ok(View::Angles(-30.0, 15.5)));
        for bad in ["w", "1", "1,2,3", "nan,1"] {
            assert!(view(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn cameras_take_negative_coordinates() {
        let c = camera("-5,2,3,0,0,0").unwrap();
        assert_eq!((c.eye, c.target, c.fov_deg), (Vec3::new(-5.0, 2.0, 3.0), Vec3::ZERO, 45.0));
        assert_eq!(camera("1,1,1,-2,-2,-2,60").unwrap().fov_deg, 60.0);
        for bad in ["1,2,3", "0,0,0,0,0,0", "1,2,3,0,0,0,180", "1,2,3,0,0,inf", "a,b,c,d,e,f"] {
            assert!(camera(bad).is_err(), "{bad}");
        }
    }
}
