//! `verne.Machine`: a machine file's parameters.

use std::path::Path;

use pyo3::exceptions::{PyOSError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use verne::spec::Machine;

/// A VERNE-type machine: geometry, limits, tilting table, tool (a machine file).
#[pyclass(name = "Machine", module = "verne", frozen)]
pub struct PyMachine {
    pub(crate) inner: Machine,
}

pub(crate) fn machine_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

#[pymethods]
impl PyMachine {
    /// The embedded VERNE machine (data/verne.toml).
    #[staticmethod]
    fn default() -> Self {
        PyMachine {
            inner: Machine::default_verne(),
        }
    }

    /// A machine file (TOML or key,value CSV); a `base` it names by path is read relative to
    /// the file. Every problem is listed in the `ValueError`.
    #[staticmethod]
    fn from_file(path: &str) -> PyResult<Self> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| PyOSError::new_err(format!("{path}: {e}")))?;
        let dir = Path::new(path)
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let resolve = |base: &str| -> Result<(String, String), String> {
            let p = dir.join(base);
            std::fs::read_to_string(&p)
                .map(|t| (t, p.display().to_string()))
                .map_err(|e| format!("base {}: {e}", p.display()))
        };
        Machine::from_str_on_base(&text, path, Some(&resolve))
            .map(|inner| PyMachine { inner })
            .map_err(machine_error)
    }

    /// A machine file's text (TOML or key,value CSV; `base = "verne"` to change a few keys).
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<Self> {
        Machine::from_str_auto(text, "<text>")
            .map(|inner| PyMachine { inner })
            .map_err(machine_error)
    }

    /// A machine from a dict shaped as the machine file, with its keys and units (lengths in mm,
    /// angles in degrees as in the file): `{"base": "verne", "tool": {"length": 120.0}}`
    /// changes a few keys of the default machine. Every problem is listed in the `ValueError`,
    /// by dotted key; a value that is not a number, bool, string, list or dict is a `TypeError`.
    ///
    /// >>> import verne
    /// >>> verne.Machine.from_dict({"base": "verne", "tool": {"length": 120.0}}).tool_length
    /// 120.0
    #[staticmethod]
    fn from_dict(d: &Bound<'_, PyDict>) -> PyResult<Self> {
        let table = dict_table(d, "")?;
        let text = toml::to_string(&table)
            .map_err(|e| PyValueError::new_err(format!("the dict as a machine file: {e}")))?;
        Machine::from_str_auto(&text, "<dict>")
            .map(|inner| PyMachine { inner })
            .map_err(|mut e| {
                // Lines of the TOML made from the dict would mean nothing to the caller.
                for p in &mut e.problems {
                    p.line = None;
                }
                machine_error(e)
            })
    }

    /// The machine as a dict of its file (`to_toml`'s keys and units), accepted by `from_dict`.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let table: toml::Table = toml::from_str(&self.inner.to_toml())
            .map_err(|e| PyValueError::new_err(format!("the machine's own TOML: {e}")))?;
        table_dict(py, &table)
    }

    /// The machine as a TOML file (degrees), readable by `from_toml` and `verne -m`.
    fn to_toml(&self) -> String {
        self.inner.to_toml()
    }

    /// The machine's name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    /// The tool length Delta (mm) of AIM 2007 eq. (8).
    #[getter]
    fn tool_length(&self) -> f64 {
        self.inner.tool_length
    }

    fn __repr__(&self) -> String {
        format!(
            "verne.Machine({:?}, tool_length={} mm)",
            self.inner.name, self.inner.tool_length
        )
    }
}

/// A dict as a TOML table, key by key; `at` is the dotted key of the dict (for messages).
fn dict_table(d: &Bound<'_, PyDict>, at: &str) -> PyResult<toml::Table> {
    let mut table = toml::Table::new();
    for (k, v) in d.iter() {
        let key: String = k.extract().map_err(|_| {
            PyTypeError::new_err(format!(
                "machine dict{}: keys must be strings, found {}",
                if at.is_empty() {
                    String::new()
                } else {
                    format!(" at {at}")
                },
                k.repr().map(|r| r.to_string()).unwrap_or_default()
            ))
        })?;
        let path = if at.is_empty() {
            key.clone()
        } else {
            format!("{at}.{key}")
        };
        table.insert(key, toml_value(&v, &path)?);
    }
    Ok(table)
}

/// One Python value as a TOML value: bool, int, float, str, list or tuple, dict.
fn toml_value(v: &Bound<'_, PyAny>, path: &str) -> PyResult<toml::Value> {
    // bool before int: a Python bool is an int.
    if v.is_instance_of::<PyBool>() {
        Ok(toml::Value::Boolean(v.extract()?))
    } else if v.is_instance_of::<PyInt>() {
        let i: i64 = v.extract().map_err(|_| {
            PyValueError::new_err(format!("machine dict: {path}: integer out of range"))
        })?;
        Ok(toml::Value::Integer(i))
    } else if v.is_instance_of::<PyFloat>() {
        Ok(toml::Value::Float(v.extract()?))
    } else if v.is_instance_of::<PyString>() {
        Ok(toml::Value::String(v.extract()?))
    } else if let Ok(d) = v.downcast::<PyDict>() {
        Ok(toml::Value::Table(dict_table(d, path)?))
    } else if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        v.try_iter()?
            .enumerate()
            .map(|(i, item)| toml_value(&item?, &format!("{path}[{i}]")))
            .collect::<PyResult<Vec<_>>>()
            .map(toml::Value::Array)
    } else if let Ok(x) = v.call_method0("__float__").and_then(|f| f.extract::<f64>()) {
        // NumPy scalars and other numbers.
        Ok(toml::Value::Float(x))
    } else {
        Err(PyTypeError::new_err(format!(
            "machine dict: {path}: expected a number, bool, string, list or dict, found {}",
            v.get_type()
                .name()
                .map(|n| n.to_string())
                .unwrap_or_default()
        )))
    }
}

/// A TOML table as a dict.
fn table_dict<'py>(py: Python<'py>, t: &toml::Table) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in t {
        d.set_item(k, toml_object(py, v)?)?;
    }
    Ok(d)
}

fn toml_object<'py>(py: Python<'py>, v: &toml::Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        toml::Value::Boolean(b) => PyBool::new(py, *b).to_owned().into_any(),
        toml::Value::Integer(i) => i.into_pyobject(py)?.into_any(),
        toml::Value::Float(x) => x.into_pyobject(py)?.into_any(),
        toml::Value::String(s) => s.into_pyobject(py)?.into_any(),
        toml::Value::Datetime(d) => d.to_string().into_pyobject(py)?.into_any(),
        toml::Value::Array(a) => {
            let items = a
                .iter()
                .map(|x| toml_object(py, x))
                .collect::<PyResult<Vec<_>>>()?;
            PyList::new(py, items)?.into_any()
        }
        toml::Value::Table(t) => table_dict(py, t)?.into_any(),
    })
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyMachine>()?;
    Ok(())
}
