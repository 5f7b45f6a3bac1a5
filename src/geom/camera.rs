//! The pinhole camera of the eye view: the one place that owns its
//! conventions.
//!
//! * Frame: `f = normalize(target - eye)`, `r = normalize(f x up)`,
//!   `u' = r x f`: r to the right, u' up, f forward; `(r, u', -f)` is
//!   right-handed (OpenGL's camera axes), and so is OpenCV's `(r, -u', f)`.
//! * Pixel `[j, i]` (row j from the top, column i from the left) has its
//!   centre at OpenCV's integer pixel coordinates `(i, j)` and the direction
//!   `f + x r + y u'` with `x = (i - cx) / fx` and `y = -(j - cy) / fy`.
//! * `look_at` is Mitsuba 3's `perspective` sensor with `fov_axis="y"` and
//!   `look_at(origin=eye, target, up)`: `fy = fx = H / (2 tan(fov_y / 2))`,
//!   `cx = (W - 1) / 2`, `cy = (H - 1) / 2`, so that
//!   `x = (-1 + 2(i + 1/2)/W) tan(fov_y/2) W/H` and
//!   `y = (1 - 2(j + 1/2)/H) tan(fov_y/2)`; `fov_y` is the full vertical
//!   angle in degrees.
//! * `from_intrinsics` takes OpenCV's K and `world_from_camera` (camera axes
//!   x right, y down, z forward): `r = x`, `u' = -y`, `f = z`. Square pixels
//!   (`fx == fy`) and no skew: the eye view's maps and Mitsuba's sensor have
//!   neither.
//!
//! Frames are computed in f64; a camera far from the origin keeps its rays.

use crate::error::{Error, Result};
use crate::geom::light::{check_resolution, finite3};
use glam::DVec3;

/// A pinhole camera: its frame in world space and its intrinsics in pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub eye: DVec3,
    /// Forward, right and up (unit, orthogonal).
    pub forward: DVec3,
    pub right: DVec3,
    pub up: DVec3,
    /// Focal length in pixels (square pixels).
    pub focal: f64,
    /// Principal point in OpenCV pixel coordinates (pixel centres at integers).
    pub cx: f64,
    pub cy: f64,
    pub width: usize,
    pub height: usize,
}

/// The most any ray direction may lean off the optical axis, in tangent
/// units: beyond it a pixel sees almost along the image plane, and f32
/// rasterization loses it. 1e6 is 89.99994 degrees, as for light-view maps.
pub const MAX_TANGENT: f64 = 1e6;

impl Camera {
    /// The camera at `eye` looking at `target`, `up` giving the image's up
    /// direction, with a full vertical field of view of `fov_y` degrees.
    pub fn look_at(
        eye: [f64; 3],
        target: [f64; 3],
        up: [f64; 3],
        fov_y: f64,
        resolution: (i64, i64),
    ) -> Result<Camera> {
        let (width, height) = check_resolution("resolution", resolution)?;
        let eye_v = finite3("eye", eye)?;
        let target_v = finite3("target", target)?;
        let up_v = finite3("up", up)?;
        if !(fov_y.is_finite() && fov_y > 0.0 && fov_y < 180.0) {
            return Err(Error::invalid(
                "fov_y",
                format!("must be a full vertical angle in (0, 180) degrees, got {fov_y}"),
            ));
        }
        let d = target_v - eye_v;
        let scale = eye_v.abs().max(target_v.abs()).max_element().max(1.0);
        if !(d.length() > 1e-12 * scale) {
            return Err(Error::invalid(
                "target",
                format!("must differ from eye, got eye {eye:?} and target {target:?}"),
            ));
        }
        let forward = d.normalize();
        if !(up_v.length() > 0.0) {
            return Err(Error::invalid("up", "must not be the zero vector"));
        }
        let r = forward.cross(up_v.normalize());
        // 1e-6 rad of parallel, as for a light's up.
        if !(r.length() > 1e-6) {
            return Err(Error::invalid(
                "up",
                format!("must not be parallel to the view direction, got up {up:?}"),
            ));
        }
        let right = r.normalize();
        let cam_up = right.cross(forward);
        let focal = height as f64 / (2.0 * (fov_y.to_radians() / 2.0).tan());
        Camera {
            eye: eye_v,
            forward,
            right,
            up: cam_up,
            focal,
            cx: (width as f64 - 1.0) / 2.0,
            cy: (height as f64 - 1.0) / 2.0,
            width,
            height,
        }
        .checked()
    }

    /// The camera of OpenCV's intrinsics `k` (row-major 3x3) and pose
    /// `world_from_camera` (row-major 4x4, rigid: a rotation and a
    /// translation).
    pub fn from_intrinsics(
        k: [[f64; 3]; 3],
        world_from_camera: [[f64; 4]; 4],
        resolution: (i64, i64),
    ) -> Result<Camera> {
        let (width, height) = check_resolution("resolution", resolution)?;
        if !k.iter().flatten().all(|x| x.is_finite()) {
            return Err(Error::invalid("K", format!("must be finite, got {k:?}")));
        }
        let [[fx, skew, cx], [k10, fy, cy], [k20, k21, k22]] = k;
        if k10 != 0.0 || k20 != 0.0 || k21 != 0.0 || k22 != 1.0 {
            return Err(Error::invalid(
                "K",
                format!("must be [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], got {k:?}"),
            ));
        }
        if skew != 0.0 {
            return Err(Error::invalid(
                "K",
                format!("skew K[0][1] must be 0 (pixels are not sheared), got {skew}"),
            ));
        }
        if !(fx > 0.0) || !(fy > 0.0) {
            return Err(Error::invalid(
                "K",
                format!("focal lengths must be > 0, got fx {fx} and fy {fy}"),
            ));
        }
        if (fx - fy).abs() > 1e-9 * fx {
            return Err(Error::invalid(
                "K",
                format!("fx and fy must be equal (square pixels), got fx {fx} and fy {fy}"),
            ));
        }
        let t = world_from_camera;
        if !t.iter().flatten().all(|x| x.is_finite()) {
            return Err(Error::invalid(
                "world_from_camera",
                format!("must be finite, got {t:?}"),
            ));
        }
        if t[3] != [0.0, 0.0, 0.0, 1.0] {
            return Err(Error::invalid(
                "world_from_camera",
                format!("the last row must be [0, 0, 0, 1], got {:?}", t[3]),
            ));
        }
        let col = |c: usize| DVec3::new(t[0][c], t[1][c], t[2][c]);
        let (x, y, z) = (col(0), col(1), col(2));
        // A rotation: orthonormal columns, right-handed (x cross y = z).
        let off = [
            x.length() - 1.0,
            y.length() - 1.0,
            z.length() - 1.0,
            x.dot(y),
            y.dot(z),
            z.dot(x),
        ];
        if off.iter().any(|e| e.abs() > 1e-6) || (x.cross(y) - z).length() > 1e-6 {
            return Err(Error::invalid(
                "world_from_camera",
                "its 3x3 part must be a rotation (orthonormal, right-handed columns)",
            ));
        }
        // The columns as given (unit within 1e-6): `world_from_camera()`
        // then gives them back bit for bit, so a camera survives the trip.
        Camera {
            eye: col(3),
            forward: z,
            right: x,
            up: -y,
            focal: fx,
            cx,
            cy,
            width,
            height,
        }
        .checked()
    }

    /// Refuses a camera whose corner pixels lean beyond MAX_TANGENT.
    fn checked(self) -> Result<Camera> {
        let tx = (self.cx.abs() + self.width as f64) / self.focal;
        let ty = (self.cy.abs() + self.height as f64) / self.focal;
        if !(tx <= MAX_TANGENT && ty <= MAX_TANGENT) {
            return Err(Error::invalid(
                "fov_y",
                format!(
                    "the image's corners lean {:.3e} off the optical axis in tangent units \
                     (limit {MAX_TANGENT:e}): the field of view is too wide",
                    tx.max(ty)
                ),
            ));
        }
        Ok(self)
    }

    /// Tangent coordinates (x, y) of pixel centre `[j, i]`.
    pub fn pixel_tangent(&self, i: usize, j: usize) -> (f64, f64) {
        (
            (i as f64 - self.cx) / self.focal,
            -(j as f64 - self.cy) / self.focal,
        )
    }

    /// The unit direction through pixel centre `[j, i]`.
    pub fn pixel_direction(&self, i: usize, j: usize) -> DVec3 {
        let (x, y) = self.pixel_tangent(i, j);
        (self.forward + x * self.right + y * self.up).normalize()
    }

    /// The full vertical field of view in degrees of a centred camera (the
    /// one `look_at` makes).
    pub fn fov_y(&self) -> f64 {
        2.0 * (self.height as f64 / (2.0 * self.focal))
            .atan()
            .to_degrees()
    }

    /// OpenCV's K (row-major).
    pub fn intrinsics(&self) -> [[f64; 3]; 3] {
        [
            [self.focal, 0.0, self.cx],
            [0.0, self.focal, self.cy],
            [0.0, 0.0, 1.0],
        ]
    }

    /// OpenCV's world_from_camera (row-major; camera x right, y down, z forward).
    pub fn world_from_camera(&self) -> [[f64; 4]; 4] {
        let (x, y, z, e) = (self.right, -self.up, self.forward, self.eye);
        [
            [x.x, y.x, z.x, e.x],
            [x.y, y.y, z.y, e.y],
            [x.z, y.z, z.z, e.z],
            [0.0, 0.0, 0.0, 1.0],
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_follows_the_documented_pixel_formula() {
        let (w, h) = (7usize, 4usize);
        let c = Camera::look_at(
            [1.0, 2.0, 3.0],
            [0.0, 0.5, 0.0],
            [0.0, 1.0, 0.0],
            40.0,
            (w as i64, h as i64),
        )
        .unwrap();
        let t = (20f64).to_radians().tan();
        for (i, j) in [(0, 0), (6, 3), (3, 1)] {
            let x = (-1.0 + 2.0 * (i as f64 + 0.5) / w as f64) * t * w as f64 / h as f64;
            let y = (1.0 - 2.0 * (j as f64 + 0.5) / h as f64) * t;
            let (cx, cy) = c.pixel_tangent(i, j);
            assert!((cx - x).abs() < 1e-12 && (cy - y).abs() < 1e-12);
        }
        assert!((c.fov_y() - 40.0).abs() < 1e-9);
        // Frame: (r, u', -f) right-handed; up has a positive world-y part.
        assert!((c.right.cross(c.up) + c.forward).length() < 1e-12);
        assert!(c.up.y > 0.0);
    }

    #[test]
    fn intrinsics_round_trip() {
        let c = Camera::look_at(
            [3.0, 2.0, 3.0],
            [0.0, 0.5, 0.0],
            [0.0, 1.0, 0.0],
            55.0,
            (64, 48),
        )
        .unwrap();
        let d = Camera::from_intrinsics(c.intrinsics(), c.world_from_camera(), (64, 48)).unwrap();
        assert_eq!(c, d);
    }

    #[test]
    fn degenerate_cameras_are_refused_by_name() {
        let arg = |r: Result<Camera>| match r {
            Err(Error::InvalidArgument { arg, .. }) | Err(Error::TooLarge { arg, .. }) => arg,
            other => panic!("{other:?}"),
        };
        let look = |eye, target, up, fov, res| Camera::look_at(eye, target, up, fov, res);
        let (o, z, y) = ([0.0; 3], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]);
        assert_eq!(arg(look(o, o, y, 40.0, (8, 8))), "target");
        assert_eq!(arg(look(o, z, z, 40.0, (8, 8))), "up");
        assert_eq!(arg(look(o, z, y, 180.0, (8, 8))), "fov_y");
        assert_eq!(arg(look(o, z, y, 0.0, (8, 8))), "fov_y");
        assert_eq!(arg(look(o, z, y, 40.0, (0, 8))), "resolution");
        assert_eq!(arg(look(o, z, y, 40.0, (1 << 20, 1 << 20))), "resolution");
        assert_eq!(arg(look([f64::NAN, 0.0, 0.0], z, y, 40.0, (8, 8))), "eye");
        let k = [[100.0, 0.0, 3.5], [0.0, 100.0, 3.5], [0.0, 0.0, 1.0]];
        let id = [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ];
        assert!(Camera::from_intrinsics(k, id, (8, 8)).is_ok());
        let mut skew = k;
        skew[0][1] = 1.0;
        assert_eq!(arg(Camera::from_intrinsics(skew, id, (8, 8))), "K");
        let mut fy = k;
        fy[1][1] = 90.0;
        assert_eq!(arg(Camera::from_intrinsics(fy, id, (8, 8))), "K");
        let mut scaled = id;
        scaled[0][0] = 2.0;
        assert_eq!(
            arg(Camera::from_intrinsics(k, scaled, (8, 8))),
            "world_from_camera"
        );
    }
}
