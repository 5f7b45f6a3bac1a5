//! The camera as a Python class (`softshadow.Camera`), on the core's
//! `geom::camera::Camera`, which owns the conventions and checks the values.

use super::convert::matrix;
use super::errors;
use crate::geom::camera::Camera;
use glam::DVec3;
use numpy::ndarray::{Array2, Array3};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use rayon::prelude::*;

/// A pinhole camera. Build it with ``Camera.look_at(...)`` (Mitsuba's
/// ``perspective`` sensor with ``fov_axis="y"``) or
/// ``Camera.from_intrinsics(K, world_from_camera, resolution=...)`` (OpenCV:
/// x right, y down, z forward). Pixel ``[j, i]`` has its centre at OpenCV's
/// ``(i, j)`` and the direction ``forward + x right + y up`` with
/// ``x = (i - cx)/f``, ``y = -(j - cy)/f``.
#[pyclass(frozen, eq, module = "softshadow._core", name = "Camera")]
#[derive(Clone, PartialEq)]
pub struct PyCamera(pub Camera);

fn vec(v: DVec3) -> (f64, f64, f64) {
    (v.x, v.y, v.z)
}

#[pymethods]
impl PyCamera {
    /// The camera of OpenCV's ``K`` (3x3, no skew, ``fx == fy``) and rigid
    /// pose ``world_from_camera`` (4x4), for an image of ``resolution`` (W, H).
    #[new]
    #[pyo3(signature = (K, world_from_camera, *, resolution))]
    #[allow(non_snake_case)]
    fn new(
        K: &Bound<'_, PyAny>,
        world_from_camera: &Bound<'_, PyAny>,
        resolution: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        let k = matrix::<3, 3>("K", K)?;
        let t = matrix::<4, 4>("world_from_camera", world_from_camera)?;
        let res = super::convert::resolution("resolution", resolution)?;
        errors::guard(|| Ok(PyCamera(Camera::from_intrinsics(k, t, res)?)))
    }

    /// The same as ``Camera(K, world_from_camera, resolution=...)``.
    #[staticmethod]
    #[pyo3(signature = (K, world_from_camera, *, resolution))]
    #[allow(non_snake_case)]
    fn from_intrinsics(
        K: &Bound<'_, PyAny>,
        world_from_camera: &Bound<'_, PyAny>,
        resolution: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        Self::new(K, world_from_camera, resolution)
    }

    /// The camera at ``eye`` looking at ``target``, ``up`` the image's up,
    /// ``fov_y`` the full vertical field of view in degrees.
    #[staticmethod]
    #[pyo3(signature = (*, eye, target, up, fov_y, resolution))]
    fn look_at(
        eye: &Bound<'_, PyAny>,
        target: &Bound<'_, PyAny>,
        up: &Bound<'_, PyAny>,
        fov_y: &Bound<'_, PyAny>,
        resolution: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        use super::convert::{float, vector};
        // Each converted by name (pyo3's own `[f64; 3]` and `f64` errors
        // named no argument).
        let (eye, target) = (vector::<3>("eye", eye)?, vector::<3>("target", target)?);
        let (up, fov_y) = (vector::<3>("up", up)?, float("fov_y", fov_y)?);
        let res = super::convert::resolution("resolution", resolution)?;
        errors::guard(|| Ok(PyCamera(Camera::look_at(eye, target, up, fov_y, res)?)))
    }

    #[getter]
    fn eye(&self) -> (f64, f64, f64) {
        vec(self.0.eye)
    }
    /// Unit view direction.
    #[getter]
    fn forward(&self) -> (f64, f64, f64) {
        vec(self.0.forward)
    }
    /// Unit image right.
    #[getter]
    fn right(&self) -> (f64, f64, f64) {
        vec(self.0.right)
    }
    /// Unit image up.
    #[getter]
    fn up(&self) -> (f64, f64, f64) {
        vec(self.0.up)
    }
    /// Full vertical field of view in degrees (of a centred camera).
    #[getter]
    fn fov_y(&self) -> f64 {
        self.0.fov_y()
    }
    /// (W, H).
    #[getter]
    fn resolution(&self) -> (usize, usize) {
        (self.0.width, self.0.height)
    }
    /// OpenCV's intrinsics (3, 3).
    #[getter]
    #[allow(non_snake_case)]
    fn K<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let k = self.0.intrinsics();
        let a = Array2::from_shape_vec((3, 3), k.iter().flatten().copied().collect())
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
        Ok(a.into_pyarray(py).into_any())
    }
    /// OpenCV's world_from_camera (4, 4): camera x right, y down, z forward.
    #[getter]
    fn world_from_camera<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let t = self.0.world_from_camera();
        let a = Array2::from_shape_vec((4, 4), t.iter().flatten().copied().collect())
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
        Ok(a.into_pyarray(py).into_any())
    }
    /// ``(K, world_from_camera)``, OpenCV's description of this camera.
    fn to_opencv<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        Ok((self.K(py)?, self.world_from_camera(py)?))
    }
    /// Mitsuba 3's ``perspective`` sensor for this camera (a dict for
    /// ``mi.load_dict``; needs ``softshadow[reference]``): pixel centres
    /// sample the same rays.
    fn to_mitsuba<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        slf.py()
            .import("softshadow.reference")?
            .call_method1("camera_sensor", (slf,))
    }
    /// Unit ray directions through every pixel centre, (H, W, 3) float64.
    fn ray_directions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let c = self.0;
        let v: Vec<f64> = py.detach(|| {
            (0..c.width * c.height)
                .into_par_iter()
                .flat_map_iter(|k| c.pixel_direction(k % c.width, k / c.width).to_array())
                .collect()
        });
        let a = Array3::from_shape_vec((c.height, c.width, 3), v)
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
        Ok(a.into_pyarray(py).into_any())
    }
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        let args = PyTuple::new(py, [self.0.intrinsics().to_vec()])?;
        let args = PyTuple::new(
            py,
            [
                args.get_item(0)?,
                self.0
                    .world_from_camera()
                    .to_vec()
                    .into_pyobject(py)?
                    .into_any(),
            ],
        )?;
        let kw = PyDict::new(py);
        kw.set_item("resolution", (self.0.width, self.0.height))?;
        Ok((args, kw))
    }
    fn __repr__(&self) -> String {
        let c = self.0;
        // Python's repr of a float is the shortest that round-trips.
        let g = |x: f64| format!("{x}");
        let f = |v: DVec3| format!("({}, {}, {})", g(v.x), g(v.y), g(v.z));
        format!(
            "Camera({}x{}, eye={}, forward={}, up={}, fov_y={:.4}, cx={}, cy={})",
            c.width,
            c.height,
            f(c.eye),
            f(c.forward),
            f(c.up),
            c.fov_y(),
            g(c.cx),
            g(c.cy)
        )
    }
}
