//! Python values to core values: types are checked here (TypeError naming
//! the argument), values by the core (ValueError from its `Error`).

use crate::backend::BackendChoice;
use crate::geom::light::AreaLight;
use crate::geom::light_space::{sphere_has_no_space, Light as CoreLight, LightSpace};
use crate::geom::mesh::MeshRef;
use crate::geom::sphere_light::SphereLight;
use crate::geom::sun::{DirectionalLight, SunSpace};
use numpy::{PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyInt, PyTuple};

/// A light as the package passes it: a rectangle (center, normal, up,
/// size), a sun (direction, up, angular_size), a sun with the
/// orthographic space of the map it made (..., depth origin, depth range),
/// a disk (center, normal, radius) or a sphere (center, radius).
#[derive(FromPyObject)]
pub enum Light {
    Rect(([f64; 3], [f64; 3], [f64; 3], [f64; 2])),
    Sun(([f64; 3], [f64; 3], [f64; 2])),
    SunSpace(([f64; 3], [f64; 3], [f64; 2], [f64; 3], f64)),
    /// A disk: (center, normal, radius).
    Disk(([f64; 3], [f64; 3], f64)),
    /// A sphere: (center, radius).
    Sphere(([f64; 3], f64)),
}

/// The light a user passed.
pub fn light_of(l: Light) -> PyResult<CoreLight> {
    Ok(match l {
        Light::Rect(l) => CoreLight::Area(AreaLight::rect(l.0, l.1, l.2, l.3)?),
        Light::Sun((d, up, a)) | Light::SunSpace((d, up, a, _, _)) => {
            CoreLight::Sun(DirectionalLight::new(d, up, a)?)
        }
        Light::Disk((c, n, r)) => CoreLight::Area(AreaLight::disk(c, n, r)?),
        Light::Sphere((c, r)) => CoreLight::Sphere(SphereLight::new(c, r)?),
    })
}

/// The light space of a map already made: a rectangle's, or a sun's with
/// its depth origin and range.
pub fn space_of(l: Light) -> PyResult<LightSpace> {
    Ok(match l {
        Light::Rect(l) => LightSpace::Area(AreaLight::rect(l.0, l.1, l.2, l.3)?),
        Light::SunSpace((d, up, a, origin, range)) => {
            let sun = DirectionalLight::new(d, up, a)?;
            let origin = crate::geom::light::finite3("depth_origin", origin)?;
            if !(range.is_finite() && range >= 0.0) {
                return Err(PyValueError::new_err(format!(
                    "depth_range: must be finite and >= 0, got {range}"
                )));
            }
            LightSpace::Sun(SunSpace::new(sun, origin, range))
        }
        Light::Sun(_) => {
            return Err(PyValueError::new_err(
                "light: a directional light's map needs its depth origin and range",
            ))
        }
        Light::Disk((c, n, r)) => LightSpace::Area(AreaLight::disk(c, n, r)?),
        Light::Sphere(_) => return Err(sphere_has_no_space().into()),
    })
}

fn type_name(v: &Bound<'_, PyAny>) -> String {
    v.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into())
}

/// Whether `v` is a bool: Python's, or numpy's (`numpy.bool`, which is not a
/// subclass of Python's).
fn is_bool(v: &Bound<'_, PyAny>) -> PyResult<bool> {
    Ok(v.is_instance_of::<PyBool>() || matches!(v.get_type().name()?.to_str()?, "bool" | "bool_"))
}

/// An int (Python or numpy; not a bool). A value beyond i64 is refused here
/// by value (the core's checks see only i64).
pub fn int(arg: &str, v: &Bound<'_, PyAny>) -> PyResult<i64> {
    if is_bool(v)? {
        return Err(PyTypeError::new_err(format!(
            "{arg}: must be an int, got bool"
        )));
    }
    match v.extract::<i64>() {
        Ok(n) => Ok(n),
        Err(_) => {
            let i = v.call_method0("__index__").map_err(|_| {
                PyTypeError::new_err(format!("{arg}: must be an int, got {}", type_name(v)))
            })?;
            Err(PyValueError::new_err(format!(
                "{arg}: {} is beyond any accepted value (64-bit integers)",
                i.cast_into::<PyInt>()?
            )))
        }
    }
}

pub fn opt_int(arg: &str, v: Option<&Bound<'_, PyAny>>) -> PyResult<Option<i64>> {
    v.filter(|v| !v.is_none()).map(|v| int(arg, v)).transpose()
}

/// A bool (Python or numpy).
pub fn opt_bool(arg: &str, v: Option<&Bound<'_, PyAny>>) -> PyResult<Option<bool>> {
    match v.filter(|v| !v.is_none()) {
        None => Ok(None),
        Some(v) => {
            if !is_bool(v)? {
                return Err(PyTypeError::new_err(format!(
                    "{arg}: must be a bool or None, got {}",
                    type_name(v)
                )));
            }
            Ok(Some(v.is_truthy()?))
        }
    }
}

/// A real number (int or float, not bool), or None.
pub fn opt_float(arg: &str, v: Option<&Bound<'_, PyAny>>) -> PyResult<Option<f64>> {
    match v.filter(|v| !v.is_none()) {
        None => Ok(None),
        Some(v) => {
            if is_bool(v)? {
                return Err(PyTypeError::new_err(format!(
                    "{arg}: must be a number, got {}",
                    type_name(v)
                )));
            }
            v.extract::<f64>().map(Some).map_err(|_| {
                PyTypeError::new_err(format!("{arg}: must be a number, got {}", type_name(v)))
            })
        }
    }
}

/// A float vector of length `N` as NumPy reads it (`np.asarray(value,
/// float64)`): TypeError for what is not numbers, ValueError for another
/// length, each naming `arg`; the core checks the values.
pub fn vector<const N: usize>(arg: &str, value: &Bound<'_, PyAny>) -> PyResult<[f64; N]> {
    if value.is_none() {
        // (NumPy reads None as a NaN of shape ().)
        return Err(PyTypeError::new_err(format!(
            "{arg}: must be a sequence of {N} numbers, got None"
        )));
    }
    let py = value.py();
    let np = py.import("numpy")?;
    let a = np
        .call_method1("asarray", (value, "float64"))
        .map_err(|_| {
            let got = value.repr().map(|r| r.to_string()).unwrap_or_default();
            PyTypeError::new_err(format!(
                "{arg}: must be a sequence of {N} numbers, got {got}"
            ))
        })?;
    let shape: Vec<usize> = a.getattr("shape")?.extract()?;
    if shape != [N] {
        let shape = PyTuple::new(py, &shape)?.repr()?.to_string();
        return Err(PyValueError::new_err(format!(
            "{arg}: must have {N} components, got shape {shape}"
        )));
    }
    let v: Vec<f64> = a.call_method0("tolist")?.extract()?;
    Ok(std::array::from_fn(|k| v[k]))
}

/// A real number (int or float, not bool): TypeError naming `arg` for
/// anything else, None included.
pub fn float(arg: &str, v: &Bound<'_, PyAny>) -> PyResult<f64> {
    opt_float(arg, Some(v))?.ok_or_else(|| {
        PyTypeError::new_err(format!("{arg}: must be a number, got {}", type_name(v)))
    })
}

/// A str.
pub fn string(arg: &str, v: &Bound<'_, PyAny>) -> PyResult<String> {
    v.extract::<String>()
        .map_err(|_| PyTypeError::new_err(format!("{arg}: must be a str, got {}", type_name(v))))
}

pub fn opt_string(arg: &str, v: Option<&Bound<'_, PyAny>>) -> PyResult<Option<String>> {
    v.filter(|v| !v.is_none())
        .map(|v| string(arg, v))
        .transpose()
}

/// `backend=`: a str naming a backend. A custom extraction so that a
/// wrong type is refused by the argument's name (pyo3's own message for a
/// `&str` names neither the argument nor the choices).
pub struct Backend(pub BackendChoice);

impl Backend {
    /// The signatures' default.
    pub const CPU: Backend = Backend(BackendChoice::Cpu);
}

impl<'a, 'py> FromPyObject<'a, 'py> for Backend {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let name = obj.extract::<String>().map_err(|_| {
            PyTypeError::new_err(format!(
                "backend: must be a str (\"cpu\", \"gpu\" or \"auto\"), got {}",
                type_name(&obj)
            ))
        })?;
        Ok(Backend(BackendChoice::parse(&name)?))
    }
}

/// A resolution: an int (square) or a pair (W, H) of ints.
pub fn resolution(arg: &str, v: &Bound<'_, PyAny>) -> PyResult<(i64, i64)> {
    if let Ok(t) = v.cast::<PyTuple>() {
        return pair(arg, t.as_any());
    }
    if v.is_instance_of::<pyo3::types::PyList>() {
        return pair(arg, v);
    }
    let n = int(arg, v).map_err(|_| {
        PyTypeError::new_err(format!(
            "{arg}: must be an int or (W, H), got {}",
            type_name(v)
        ))
    })?;
    Ok((n, n))
}

fn pair(arg: &str, v: &Bound<'_, PyAny>) -> PyResult<(i64, i64)> {
    let n = v.len()?;
    if n != 2 {
        return Err(PyValueError::new_err(format!(
            "{arg}: must be an int or (W, H), got {n} values"
        )));
    }
    Ok((int(arg, &v.get_item(0)?)?, int(arg, &v.get_item(1)?)?))
}

pub fn opt_resolution(arg: &str, v: Option<&Bound<'_, PyAny>>) -> PyResult<Option<(i64, i64)>> {
    v.filter(|v| !v.is_none())
        .map(|v| resolution(arg, v))
        .transpose()
}

/// Borrows a C-contiguous array as a slice, naming the argument if it is not.
pub fn slice<'a, T: numpy::Element, D: numpy::ndarray::Dimension>(
    arg: &str,
    a: &'a numpy::PyReadonlyArray<'_, T, D>,
) -> PyResult<&'a [T]> {
    a.as_slice()
        .map_err(|_| PyValueError::new_err(format!("{arg}: must be a C-contiguous array")))
}

/// Reinterprets a (n, 3) array's buffer as n triples.
pub fn triples<'a, T: numpy::Element>(
    arg: &str,
    a: &'a PyReadonlyArray2<'_, T>,
) -> PyResult<&'a [[T; 3]]> {
    if a.shape()[1] != 3 {
        return Err(PyValueError::new_err(format!(
            "{arg}: must have shape (n, 3), got {:?}",
            a.shape()
        )));
    }
    let s = slice(arg, a)?;
    // SAFETY: [T; 3] has T's alignment and no padding; the buffer is
    // contiguous with a multiple of 3 elements, and it outlives the borrow.
    Ok(unsafe { std::slice::from_raw_parts(s.as_ptr() as *const [T; 3], s.len() / 3) })
}

/// A mesh from its (n, 3) vertex and face arrays.
pub fn mesh<'a>(
    arg: &str,
    vertices: &'a PyReadonlyArray2<'_, f64>,
    faces: &'a PyReadonlyArray2<'_, u32>,
) -> PyResult<MeshRef<'a>> {
    Ok(MeshRef {
        vertices: triples(arg, vertices)?,
        faces: triples(arg, faces)?,
    })
}

pub fn same_shape(arg: &str, got: &[usize], want: &[usize]) -> PyResult<()> {
    if got == want {
        Ok(())
    } else {
        Err(PyValueError::new_err(format!(
            "{arg}: shape {got:?} differs from {want:?}"
        )))
    }
}

/// An R x C matrix of numbers (nested sequences or a numpy array).
pub fn matrix<const R: usize, const C: usize>(
    arg: &str,
    v: &Bound<'_, PyAny>,
) -> PyResult<[[f64; C]; R]> {
    if v.is_instance_of::<pyo3::types::PyString>() || v.is_instance_of::<pyo3::types::PyBytes>() {
        return Err(PyTypeError::new_err(format!(
            "{arg}: must be a {R}x{C} matrix of numbers, got {}",
            type_name(v)
        )));
    }
    v.extract::<[[f64; C]; R]>().map_err(|e| {
        PyValueError::new_err(format!(
            "{arg}: must be a {R}x{C} matrix of numbers ({})",
            e.value(v.py())
        ))
    })
}
