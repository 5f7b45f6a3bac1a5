//! One description per config class, and the Python class made from it:
//! `config_class!` takes the class's constructor (its keyword-only
//! signature and the core constructor it calls) and its options, each once
//! (name, type, how to read it off the core config), and writes the frozen
//! pyclass with a getter per option, `to_dict` (the options as keyword
//! arguments, so that `Class(**c.to_dict()) == c`), pickling through the
//! keyword-only constructor (`__getnewargs_ex__`) and `repr`
//! (`Class(option=value, ...)`, each value as Python writes it).

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

/// A value as Python's `repr` writes it.
pub trait PyRepr {
    fn py_repr(&self, py: Python<'_>) -> PyResult<String>;
}

macro_rules! repr_display {
    ($($t:ty),*) => {
        $(impl PyRepr for $t {
            fn py_repr(&self, _py: Python<'_>) -> PyResult<String> {
                Ok(self.to_string())
            }
        })*
    };
}
repr_display!(u32, i64, usize);

impl PyRepr for f64 {
    /// The shortest string that reads back as the same float.
    fn py_repr(&self, _py: Python<'_>) -> PyResult<String> {
        Ok(format!("{self:?}"))
    }
}

impl PyRepr for bool {
    fn py_repr(&self, _py: Python<'_>) -> PyResult<String> {
        Ok(if *self { "True" } else { "False" }.into())
    }
}

impl PyRepr for &str {
    fn py_repr(&self, _py: Python<'_>) -> PyResult<String> {
        Ok(format!("'{self}'"))
    }
}

impl<A: PyRepr, B: PyRepr> PyRepr for (A, B) {
    fn py_repr(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "({}, {})",
            self.0.py_repr(py)?,
            self.1.py_repr(py)?
        ))
    }
}

impl<T: PyRepr> PyRepr for Option<T> {
    fn py_repr(&self, py: Python<'_>) -> PyResult<String> {
        match self {
            None => Ok("None".into()),
            Some(v) => v.py_repr(py),
        }
    }
}

/// An option's value from the core's table (`keyword_class.rs`).
impl PyRepr for crate::methods::info::Value {
    fn py_repr(&self, py: Python<'_>) -> PyResult<String> {
        use crate::methods::info::Value;
        match *self {
            Value::Resolved => Ok("None".into()),
            Value::Int(n) => n.py_repr(py),
            Value::Bool(b) => b.py_repr(py),
            Value::Str(s) => s.py_repr(py),
            Value::Float(x) => x.py_repr(py),
            Value::Pair(w, h) => (w, h).py_repr(py),
        }
    }
}

impl<T> PyRepr for Py<T> {
    fn py_repr(&self, py: Python<'_>) -> PyResult<String> {
        Ok(self.bind(py).as_any().repr()?.to_string())
    }
}

/// `(args, kwargs)` for pickle: no positional arguments, the options.
pub fn newargs<'py>(
    py: Python<'py>,
    d: Bound<'py, PyDict>,
) -> (Bound<'py, PyTuple>, Bound<'py, PyDict>) {
    (PyTuple::empty(py), d)
}

/// A config class. `name` adds the `name` getter (the string `method=`
/// takes); each option is `option: Type = |config, py| value`, `config`
/// the class's instance.
macro_rules! config_class {
    (
        $(#[doc = $doc:literal])*
        class $class:ident $(($inner:ty))? as $py_name:literal $(, name $method:literal)?;
        #[pyo3(signature = $sig:tt)]
        fn new($($arg:ident: $arg_ty:ty),* $(,)?) -> PyResult<Self> $new:block
        options {
            $($option:ident: $ty:ty = |$c:ident, $py:ident| $get:expr;)*
        }
    ) => {
        $(#[doc = $doc])*
        #[pyo3::pyclass(frozen, eq, hash, module = "softshadow._core", name = $py_name)]
        #[derive(Clone, PartialEq, Eq, Hash)]
        pub struct $class $((pub $inner))?;

        $(
            impl From<$inner> for $class {
                fn from(c: $inner) -> Self {
                    $class(c)
                }
            }

            impl From<&$class> for $inner {
                fn from(c: &$class) -> Self {
                    c.0
                }
            }
        )?

        #[pyo3::pymethods]
        impl $class {
            #[new]
            #[pyo3(signature = $sig)]
            fn new($($arg: $arg_ty),*) -> PyResult<Self> $new

            $(
                #[doc = concat!("\"", $method, "\", the name given as ``method=``.")]
                #[getter]
                fn name(&self) -> &'static str {
                    $method
                }
            )?

            $(
                #[getter]
                #[allow(unused_variables)]
                fn $option(&self, py: Python<'_>) -> PyResult<$ty> {
                    let ($c, $py) = (self, py);
                    Ok($get)
                }
            )*

            /// The options as keyword arguments: ``Class(**c.to_dict()) == c``.
            #[allow(unused_variables)]
            fn to_dict<'py>(
                &self,
                py: Python<'py>,
            ) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
                let d = pyo3::types::PyDict::new(py);
                $(d.set_item(stringify!($option), self.$option(py)?)?;)*
                Ok(d)
            }

            fn __getnewargs_ex__<'py>(
                &self,
                py: Python<'py>,
            ) -> PyResult<(Bound<'py, pyo3::types::PyTuple>, Bound<'py, pyo3::types::PyDict>)> {
                Ok($crate::python::config_class::newargs(py, self.to_dict(py)?))
            }

            #[allow(unused_variables, unused_mut)]
            fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
                #[allow(unused_imports)]
                use $crate::python::config_class::PyRepr;
                let mut parts: Vec<String> = Vec::new();
                $(parts.push(format!(
                    "{}={}",
                    stringify!($option),
                    self.$option(py)?.py_repr(py)?
                ));)*
                Ok(format!("{}({})", $py_name, parts.join(", ")))
            }
        }
    };
}

pub(crate) use config_class;
