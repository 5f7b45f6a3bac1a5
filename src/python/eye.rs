//! The eye view's entry point and its result: converts the arguments, runs
//! `eye::render_shaded` without the GIL, moves the G-buffer, the shaded
//! images and the maps into arrays. Also the shading's own entry points
//! (`light_emission`, `irradiance`: the lights' checks and closed forms).

use super::camera::PyCamera;
use super::configs::{self, method_arg, Loose};
use super::convert::{
    light_of, mesh, opt_float, opt_int, opt_resolution, opt_string, triples, Backend, Light,
};
use super::errors;
use super::prepared::PyPrepared;
use super::results::{map, sun_depth};
use crate::api::Run;
use crate::error_estimate::Draw;
use crate::eye::albedo::{Material, Varies};
use crate::eye::shading::{self, ColorValue};
use crate::eye::{Bias, EyeCall, EyeImage, Lighting, Shaded};
use crate::geom::mesh::MeshRef;
use crate::timing::Timings;
use numpy::ndarray::{Array2, Array3};
use numpy::{
    IntoPyArray, PyArrayDyn, PyReadonlyArray2, PyReadonlyArray3, PyReadonlyArrayDyn,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

/// Nesting beyond this is refused as a type (a colour list is at most a
/// list of triples).
const MAX_COLOR_DEPTH: usize = 2;

/// A number or a (nested) list or tuple of numbers, for the core to read as
/// colours (`shading::ColorValue`); `arg` names it in a TypeError.
fn color_value(arg: &str, v: &Bound<'_, PyAny>, depth: usize) -> PyResult<ColorValue> {
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        if depth >= MAX_COLOR_DEPTH {
            return Err(PyTypeError::new_err(format!(
                "{arg}: must be a number or a sequence of numbers or triples, got deeper nesting"
            )));
        }
        let items = v
            .try_iter()?
            .map(|item| color_value(arg, &item?, depth + 1))
            .collect::<PyResult<_>>()?;
        return Ok(ColorValue::List(items));
    }
    match opt_float(arg, Some(v)) {
        Ok(Some(x)) => Ok(ColorValue::Number(x)),
        _ => Err(PyTypeError::new_err(format!(
            "{arg}: must be a number or a sequence of numbers, got {}",
            v.get_type().name()?
        ))),
    }
}

fn opt_color(arg: &str, v: Option<&Bound<'_, PyAny>>) -> PyResult<Option<ColorValue>> {
    v.filter(|v| !v.is_none())
        .map(|v| color_value(arg, v, 0))
        .transpose()
}

/// A light's emission checked by the core: `arg` ("radiance" or
/// "irradiance") is a number or an RGB triple, or None for the default.
#[pyfunction]
#[pyo3(signature = (arg, value=None))]
pub fn light_emission(arg: &str, value: Option<Bound<'_, PyAny>>) -> PyResult<[f64; 3]> {
    errors::guard(|| {
        Ok(shading::emission(
            arg,
            opt_color(arg, value.as_ref())?.as_ref(),
        )?)
    })
}

/// The unshadowed irradiance (N, 3) at world points (N, 3) with normals
/// (N, 3), the light's emission (RGB) included.
#[pyfunction]
#[pyo3(signature = (light, points, normals, emission=None))]
pub fn irradiance<'py>(
    py: Python<'py>,
    light: Light,
    points: PyReadonlyArray2<'py, f64>,
    normals: PyReadonlyArray2<'py, f64>,
    emission: Option<Bound<'py, PyAny>>,
) -> PyResult<Py<PyAny>> {
    errors::guard(|| {
        let light = light_of(light)?;
        let arg = shading::emission_arg(&light);
        let emission = shading::emission(arg, opt_color(arg, emission.as_ref())?.as_ref())?;
        let p = triples("points", &points)?;
        let n = triples("normals", &normals)?;
        let e = py.detach(|| shading::irradiance_at(&light, emission, p, n))?;
        let rows = e.len();
        let a = Array2::from_shape_vec((rows, 3), e.into_flattened())
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(a.into_pyarray(py).into_any().unbind())
    })
}

/// sRGB-encoded values in [0, 1] (any shape; clipped) -> linear f32
/// (`eye::albedo::srgb_to_linear`).
#[pyfunction]
pub fn srgb_to_linear<'py>(
    py: Python<'py>,
    values: PyReadonlyArrayDyn<'py, f64>,
) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
    let a = values.as_array();
    Ok(a.mapv(|x| crate::eye::albedo::srgb_to_linear(x) as f32)
        .into_pyarray(py))
}

/// A scene seen through a camera -> the visibility image and its G-buffer.
#[pyfunction]
#[pyo3(signature = (meshes, lights, camera, method, *, map_resolution=None, normal_offset=None, depth_bias=None, passes=None, samples=None, occluder_resolution=None, hierarchy=None, precision=None, backend=Backend::CPU, threads=None, emission=None, albedo=None, estimate_error=None, prepared=None, materials=None))]
#[allow(clippy::too_many_arguments)]
pub fn render<'py>(
    py: Python<'py>,
    meshes: Vec<(PyReadonlyArray2<'py, f64>, PyReadonlyArray2<'py, u32>)>,
    lights: Vec<Light>,
    camera: &PyCamera,
    method: &Bound<'py, PyAny>,
    map_resolution: Option<Bound<'py, PyAny>>,
    normal_offset: Option<Bound<'py, PyAny>>,
    depth_bias: Option<Bound<'py, PyAny>>,
    passes: Option<Bound<'py, PyAny>>,
    samples: Option<Bound<'py, PyAny>>,
    occluder_resolution: Option<Bound<'py, PyAny>>,
    hierarchy: Option<Bound<'py, PyAny>>,
    precision: Option<Bound<'py, PyAny>>,
    backend: Backend,
    threads: Option<Bound<'py, PyAny>>,
    emission: Option<Vec<Option<Bound<'py, PyAny>>>>,
    albedo: Option<Bound<'py, PyAny>>,
    estimate_error: Option<Bound<'py, PyAny>>,
    prepared: Option<Bound<'py, PyPrepared>>,
    materials: Option<Vec<Option<MaterialArgs<'py>>>>,
) -> PyResult<Vec<EyeResult>> {
    errors::guard(|| {
        let lights = lights
            .into_iter()
            .map(light_of)
            .collect::<PyResult<Vec<_>>>()?;
        let emission = emission.unwrap_or_default();
        if !emission.is_empty() && emission.len() != lights.len() {
            return Err(PyValueError::new_err(format!(
                "emission: {} emissions for {} lights",
                emission.len(),
                lights.len()
            )));
        }
        let albedo = opt_color("albedo", albedo.as_ref())?;
        let lit = lights
            .iter()
            .enumerate()
            .map(|(k, light)| {
                let arg = shading::emission_arg(light);
                let e = emission.get(k).and_then(|e| e.as_ref());
                let lighting = Lighting::new(
                    light,
                    opt_color(arg, e)?.as_ref(),
                    albedo.as_ref(),
                    meshes.len(),
                )?;
                Ok((*light, lighting))
            })
            .collect::<PyResult<Vec<_>>>()?;
        let Some((first, _)) = lit.first() else {
            return Err(PyValueError::new_err(
                "lights: must hold at least one light",
            ));
        };
        let loose = Loose {
            passes,
            samples,
            occluder_resolution,
            hierarchy,
            precision,
        };
        let refs: Vec<MeshRef> = meshes
            .iter()
            .enumerate()
            .map(|(k, (v, f))| mesh(&format!("meshes[{k}]"), v, f))
            .collect::<PyResult<_>>()?;
        let call = EyeCall {
            meshes: &refs,
            light: first,
            camera: &camera.0,
            method: method_arg(method, &loose)?,
            map_resolution: opt_resolution("map_resolution", map_resolution.as_ref())?,
            bias: Bias::new(
                opt_float("normal_offset", normal_offset.as_ref())?,
                opt_float("depth_bias", depth_bias.as_ref())?,
            )?,
            backend: backend.0,
            threads: opt_int("threads", threads.as_ref())?,
            estimate_error: opt_string("estimate_error", estimate_error.as_ref())?
                .as_deref()
                .map(Draw::parse)
                .transpose()?,
            prepared: prepared.as_ref().map(|p| &p.get().0),
            gbuffer: None,
        };
        // `albedo=` overrides the meshes' own colours.
        let held = match (&albedo, materials) {
            (None, Some(m)) => m
                .into_iter()
                .enumerate()
                .map(|(k, m)| {
                    m.map(|m| held_material(&format!("materials[{k}]"), m))
                        .transpose()
                })
                .collect::<PyResult<Vec<_>>>()?,
            _ => vec![],
        };
        let mats: Vec<Option<Material>> = held
            .iter()
            .map(|h| h.as_ref().map(HeldMaterial::material).transpose())
            .collect::<PyResult<_>>()?;
        let runs = super::interrupt::run(py, || crate::api::render_lights(&call, &lit, &mats))?;
        runs.into_iter()
            .map(|(run, shaded)| EyeResult::new(py, run, shaded))
            .collect()
    })
}

/// A mesh's material as the package passes it (`Material.to_core()`):
/// kind, linear colour, then its arrays (colours, or UVs and texture).
type MaterialArgs<'py> = (
    String,
    [f64; 3],
    Option<Bound<'py, PyAny>>,
    Option<Bound<'py, PyAny>>,
);

/// A material's arrays, held (borrowed from NumPy) while the call runs.
enum HeldMaterial<'py> {
    Constant([f64; 3]),
    Vertex([f64; 3], PyReadonlyArray2<'py, f32>),
    Face([f64; 3], PyReadonlyArray2<'py, f32>),
    Texture(
        [f64; 3],
        PyReadonlyArray2<'py, f32>,
        PyReadonlyArray3<'py, u8>,
    ),
}

/// The arrays of a material `(kind, color, a, b)`, named `arg` in errors.
fn held_material<'py>(
    arg: &str,
    (kind, color, a, b): MaterialArgs<'py>,
) -> PyResult<HeldMaterial<'py>> {
    let array = |what: &str, v: Option<Bound<'py, PyAny>>| {
        v.ok_or_else(|| {
            PyValueError::new_err(format!("{arg}: a {kind:?} material needs its {what}"))
        })
    };
    let rows = |what: &str,
                v: Option<Bound<'py, PyAny>>,
                cols: usize|
     -> PyResult<PyReadonlyArray2<'py, f32>> {
        let a: PyReadonlyArray2<'py, f32> = array(what, v)?.extract().map_err(|_| {
            PyTypeError::new_err(format!("{arg}: {what} must be a 2-d float32 array"))
        })?;
        if a.shape()[1] != cols || !a.is_c_contiguous() {
            return Err(PyValueError::new_err(format!(
                "{arg}: {what} must be C-contiguous (N, {cols}), got {:?}",
                a.shape()
            )));
        }
        Ok(a)
    };
    Ok(match kind.as_str() {
        "constant" => HeldMaterial::Constant(color),
        "vertex" => HeldMaterial::Vertex(color, rows("colours", a, 3)?),
        "face" => HeldMaterial::Face(color, rows("colours", a, 3)?),
        "texture" => {
            let uv = rows("UVs", a, 2)?;
            let t: PyReadonlyArray3<'py, u8> = array("texture", b)?.extract().map_err(|_| {
                PyTypeError::new_err(format!("{arg}: texture must be a (H, W, 3) uint8 array"))
            })?;
            if t.shape()[2] != 3 || !t.is_c_contiguous() {
                return Err(PyValueError::new_err(format!(
                    "{arg}: texture must be C-contiguous (H, W, 3), got {:?}",
                    t.shape()
                )));
            }
            HeldMaterial::Texture(color, uv, t)
        }
        other => {
            return Err(PyValueError::new_err(format!(
                "{arg}: unknown material kind {other:?}"
            )))
        }
    })
}

impl HeldMaterial<'_> {
    /// The core's view of the arrays.
    fn material(&self) -> PyResult<Material<'_>> {
        fn slice2<'a>(a: &'a PyReadonlyArray2<'_, f32>) -> PyResult<&'a [f32]> {
            a.as_slice()
                .map_err(|e| PyValueError::new_err(e.to_string()))
        }
        Ok(match self {
            HeldMaterial::Constant(color) => Material {
                color: *color,
                varies: Varies::Constant,
            },
            HeldMaterial::Vertex(color, c) => Material {
                color: *color,
                varies: Varies::Vertex(slice2(c)?.as_chunks::<3>().0),
            },
            HeldMaterial::Face(color, c) => Material {
                color: *color,
                varies: Varies::Face(slice2(c)?.as_chunks::<3>().0),
            },
            HeldMaterial::Texture(color, uv, t) => {
                let texels = t
                    .as_slice()
                    .map_err(|e| PyValueError::new_err(e.to_string()))?;
                Material {
                    color: *color,
                    varies: Varies::Texture {
                        uv: slice2(uv)?.as_chunks::<2>().0,
                        texels: texels.as_chunks::<3>().0,
                        width: t.shape()[1],
                        height: t.shape()[0],
                    },
                }
            }
        })
    }
}

/// An image: visibility, G-buffer, the light-view maps, and what ran it.
#[pyclass(frozen, module = "softshadow._core", name = "EyeResult")]
pub struct EyeResult {
    /// (H, W) float32; 1 where no surface.
    #[pyo3(get)]
    visibility: Py<PyAny>,
    /// (H, W, 3) float32 outgoing radiance, unshadowed times visibility; 0
    /// where no surface.
    #[pyo3(get)]
    shaded: Py<PyAny>,
    /// (H, W, 3) float32 outgoing radiance without shadows; 0 where no surface.
    #[pyo3(get)]
    unshadowed: Py<PyAny>,
    /// (H, W, 3) float32 albedo each pixel was shaded with; 0 where no surface.
    #[pyo3(get)]
    albedo: Py<PyAny>,
    /// (H, W) float32 distance along the optical axis; inf where no surface.
    #[pyo3(get)]
    depth: Py<PyAny>,
    /// (H, W, 3) float64 world position; NaN where no surface.
    #[pyo3(get)]
    position: Py<PyAny>,
    /// (H, W, 3) float32 unit geometric normal facing the camera.
    #[pyo3(get)]
    normal: Py<PyAny>,
    /// (H, W) int32 mesh index, -1 where no surface.
    #[pyo3(get)]
    mesh_id: Py<PyAny>,
    /// The map methods' occluder layers, front first (empty for exact).
    #[pyo3(get)]
    shadow_maps: Vec<Py<PyAny>>,
    /// Their half-extents: tangents, or world units for the sun.
    #[pyo3(get)]
    map_extent: Option<(f64, f64)>,
    /// For the sun: the maps' depth origin and depth range.
    #[pyo3(get)]
    depth_origin: Option<(f64, f64, f64)>,
    #[pyo3(get)]
    depth_range: Option<f64>,
    timings: Timings,
    #[pyo3(get)]
    method: Py<PyAny>,
    #[pyo3(get)]
    backend: &'static str,
    #[pyo3(get)]
    threads: usize,
    /// What `Auto` with a target decided: (name, taken, why) per decision.
    #[pyo3(get)]
    plan: Option<Vec<(&'static str, bool, String)>>,
    /// The setting the plan chose, where runs checked against its estimate
    /// replaced it; else None.
    #[pyo3(get)]
    planned_method: Option<Py<PyAny>>,
    /// The error estimate (`estimate_error=True`, or `Auto` with a target),
    /// else None.
    #[pyo3(get)]
    error_estimate: Option<Py<super::estimate::PyErrorEstimate>>,
}

#[pymethods]
impl EyeResult {
    /// Seconds per stage, in the order they ran.
    #[getter]
    fn timings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.timings {
            d.set_item(*k, *v)?;
        }
        Ok(d)
    }
}

fn image3<T: numpy::Element>(py: Python<'_>, h: usize, w: usize, v: Vec<T>) -> PyResult<Py<PyAny>> {
    let a =
        Array3::from_shape_vec((h, w, 3), v).map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py).into_any().unbind())
}

fn image2<T: numpy::Element>(py: Python<'_>, h: usize, w: usize, v: Vec<T>) -> PyResult<Py<PyAny>> {
    let a = Array2::from_shape_vec((h, w), v).map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py).into_any().unbind())
}

impl EyeResult {
    fn new(py: Python<'_>, run: Run<EyeImage>, shaded: Shaded) -> PyResult<Self> {
        let img = run.output;
        let g = img.gbuffer;
        let (w, h) = (g.width, g.height);
        let (map_extent, shadow_maps) = match img.maps {
            Some(m) => {
                let e = img.light_space.map_or([m.grid.tx, m.grid.ty], |s| {
                    s.user_extent([m.grid.tx, m.grid.ty])
                });
                let grid = m.grid;
                let layers = m
                    .layers
                    .into_iter()
                    .map(|l| map(py, &grid, l))
                    .collect::<PyResult<_>>()?;
                (Some((e[0], e[1])), layers)
            }
            None => (None, vec![]),
        };
        let (depth_origin, depth_range) = sun_depth(img.light_space.as_ref());
        Ok(EyeResult {
            visibility: image2(py, h, w, img.visibility)?,
            shaded: image3(py, h, w, shaded.shaded.into_flattened())?,
            unshadowed: image3(py, h, w, shaded.unshadowed.into_flattened())?,
            albedo: image3(py, h, w, shaded.albedo.into_flattened())?,
            depth: image2(py, h, w, g.depth)?,
            position: image3(py, h, w, g.position.into_flattened())?,
            normal: image3(py, h, w, g.normal.into_flattened())?,
            mesh_id: image2(py, h, w, g.mesh_id)?,
            shadow_maps,
            map_extent,
            depth_origin,
            depth_range,
            timings: img.timings,
            method: configs::to_py(py, &run.method)?,
            backend: run.backend.name(),
            threads: run.threads,
            planned_method: (run.plan.as_ref())
                .and_then(|p| p.planned)
                .map(|m| configs::to_py(py, &m))
                .transpose()?,
            plan: super::results::plan_tuples(run.plan),
            error_estimate: img
                .estimate
                .map(|e| Py::new(py, super::estimate::PyErrorEstimate(e)))
                .transpose()?,
        })
    }
}
