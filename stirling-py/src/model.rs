//! A model by name (the family, its aliases, a registered engine) and what it declares:
//! states, bodies, parameters with units and bounds, sensors, effect sites, equations; the
//! right-hand side and its Jacobians at a state.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use stirling_dsl::{Closure, JacSink, Model, StateKind, Style};
use stirling_models::{user_models, FAMILY};

use crate::arrays::{array1, col_major, vector};
use crate::errors::{Failure, Kind, Res};

/// A built model: the library's `Box<dyn Model>` and the name it was asked for.
#[pyclass(module = "stirling._native", frozen)]
pub struct NativeModel {
    pub model: Box<dyn Model>,
    /// The name as given (an alias such as `order8` stays `order8`), for the rig and the
    /// diagnosis, which build their own members by name.
    pub requested: String,
    /// `n` as given (`None`: the default).
    pub n_given: Option<usize>,
}

impl NativeModel {
    /// The bond graph of the model.
    pub fn bond(&self) -> Res<stirling_dsl::bond::CausalGraph> {
        stirling_dsl::bond::bond_graph(self.model.as_ref())
            .map_err(|e| Failure::new(Kind::Model, e.to_string()))
    }

    pub fn dyn_model(&self) -> &dyn Model {
        self.model.as_ref()
    }

    /// The parameter vector `p` checked against the model (length, finite).
    pub fn params_of(&self, p: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
        let n = self.model.params().len();
        vector(
            p,
            "the parameter vector",
            Some((n, &format!("the parameters of `{}`", self.model.name()))),
        )
    }

    /// A state vector `x` checked against the model.
    pub fn state_of(&self, x: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
        let m = self.dyn_model();
        let of = format!(
            "the states of `{}`: {}",
            m.name(),
            m.state_names().join(", ")
        );
        vector(x, what, Some((m.n_states(), &of)))
    }
}

fn closure(s: &str) -> Res<Closure> {
    s.parse::<Closure>()
        .map_err(|e| Failure::new(Kind::Model, e))
}

fn kind_name(k: StateKind) -> (&'static str, usize) {
    match k {
        StateKind::Position(i) => ("position", i),
        StateKind::Velocity(i) => ("velocity", i),
        StateKind::Pressure(i) => ("pressure", i),
        StateKind::Mass(i) => ("mass", i),
        StateKind::WallTemperature(i) => ("wall_temperature", i),
    }
}

fn style(s: &str) -> Res<Style> {
    match s {
        "text" => Ok(Style::Text),
        "latex" => Ok(Style::Latex),
        _ => Err(Failure::option(format!(
            "unknown style `{s}`: expected `text` or `latex`"
        ))),
    }
}

#[pymethods]
impl NativeModel {
    #[new]
    #[pyo3(signature = (name, n=None, closure="full"))]
    fn new(name: &str, n: Option<usize>, closure: &str) -> PyResult<Self> {
        let c = self::closure(closure)?;
        let model = stirling_models::build(name, n, c).map_err(Failure::from)?;
        Ok(NativeModel {
            model,
            requested: name.to_string(),
            n_given: n,
        })
    }

    #[getter]
    fn name(&self) -> &'static str {
        self.model.name()
    }

    #[getter]
    fn requested(&self) -> &str {
        &self.requested
    }

    #[getter]
    fn n(&self) -> usize {
        self.model.n()
    }

    #[getter]
    fn closure(&self) -> &'static str {
        self.model.closure().as_str()
    }

    #[getter]
    fn n_states(&self) -> usize {
        self.model.n_states()
    }

    #[getter]
    fn has_array(&self) -> bool {
        self.model.has_array()
    }

    /// The states in order: name, kind, index of its body or vessel, unit, meaning.
    fn states<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let out = PyList::empty(py);
        for s in self.model.states() {
            let d = PyDict::new(py);
            let (kind, index) = kind_name(s.kind);
            d.set_item("name", s.name)?;
            d.set_item("kind", kind)?;
            d.set_item("index", index)?;
            d.set_item("unit", s.unit)?;
            d.set_item("meaning", s.meaning)?;
            out.append(d)?;
        }
        Ok(out)
    }

    /// The bodies: name, position state, velocity state.
    fn bodies<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let out = PyList::empty(py);
        for b in self.model.bodies() {
            let d = PyDict::new(py);
            d.set_item("name", b.name)?;
            d.set_item("position", b.pos)?;
            d.set_item("velocity", b.vel)?;
            out.append(d)?;
        }
        Ok(out)
    }

    /// The parameters in vector order: name, default, unit, doc, declared bounds.
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let out = PyList::empty(py);
        for p in self.model.params() {
            let d = PyDict::new(py);
            d.set_item("name", p.name)?;
            d.set_item("default", p.default)?;
            d.set_item("unit", p.unit)?;
            d.set_item("doc", p.doc)?;
            d.set_item("bounds", p.bounds)?;
            out.append(d)?;
        }
        Ok(out)
    }

    /// The declared sensors: name, state or expression, the states read, unit.
    fn sensors<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let out = PyList::empty(py);
        for s in self.model.sensors() {
            let d = PyDict::new(py);
            d.set_item("name", s.name)?;
            d.set_item("definition", s.definition())?;
            d.set_item("reads", s.reads.to_vec())?;
            d.set_item("unit", s.unit)?;
            out.append(d)?;
        }
        Ok(out)
    }

    /// The effects the model names where they act (`effect coulomb on piston;`).
    fn effect_sites<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let out = PyList::empty(py);
        for e in self.model.effect_sites() {
            let d = PyDict::new(py);
            d.set_item("effect", e.effect)?;
            d.set_item("at", e.at)?;
            d.set_item("params", e.params.to_vec())?;
            out.append(d)?;
        }
        Ok(out)
    }

    /// The parameters a fit frees by default (`free kd, kp;`).
    fn declared_free(&self) -> Vec<&'static str> {
        self.model.declared_free().to_vec()
    }

    /// The gas vessels (control volumes, then spaces), in the order of `pv`.
    fn vessel_names(&self) -> Vec<String> {
        self.model.vessel_names()
    }

    /// The generated equations, as text or LaTeX.
    fn equations(&self, style: &str) -> PyResult<String> {
        Ok(self.model.equations(self::style(style)?))
    }

    /// The bond graph as Graphviz DOT (junctions, causal strokes, half-arrows), as
    /// `stirling info --graph` writes it.
    fn dot(&self) -> Res<String> {
        Ok(self.bond()?.to_dot())
    }

    /// The bond graph drawn as SVG (no Graphviz needed), as `stirling info --graph --svg`.
    fn bond_svg(&self) -> Res<String> {
        Ok(self.bond()?.to_svg())
    }

    /// The parameter vector: `base` (default: the defaults) with `values` by name, validated.
    #[pyo3(signature = (values=None, base=None))]
    fn params<'py>(
        &self,
        py: Python<'py>,
        values: Option<&Bound<'py, PyDict>>,
        base: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let base = base.map(|b| self.params_of(b)).transpose()?;
        Ok(array1(py, crate::params::apply(self.dyn_model(), base, values)?).into_any())
    }

    /// `f(x, p, t)`.
    fn rhs<'py>(
        &self,
        py: Python<'py>,
        p: &Bound<'py, PyAny>,
        x: &Bound<'py, PyAny>,
        t: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (p, x) = (self.params_of(p)?, self.state_of(x, "x")?);
        let mut out = vec![0.0; x.len()];
        self.model.rhs(&p, &x, t, &mut out);
        Ok(array1(py, out).into_any())
    }

    /// `df/dx` (n x n).
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        p: &Bound<'py, PyAny>,
        x: &Bound<'py, PyAny>,
        t: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (p, x) = (self.params_of(p)?, self.state_of(x, "x")?);
        let n = x.len();
        Ok(col_major(py, self.model.jacobian_dense(&p, &x, t), n, n).into_any())
    }

    /// `f` and `df/dx` in one call (the generated code shares their common values).
    fn rhs_and_jacobian<'py>(
        &self,
        py: Python<'py>,
        p: &Bound<'py, PyAny>,
        x: &Bound<'py, PyAny>,
        t: f64,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let (p, x) = (self.params_of(p)?, self.state_of(x, "x")?);
        let n = x.len();
        let mut f = vec![0.0; n];
        let mut data = vec![0.0; n * n];
        self.model.rhs_and_jacobian(
            &p,
            &x,
            t,
            &mut f,
            &mut JacSink::Dense {
                data: &mut data,
                nrows: n,
            },
        );
        Ok((
            array1(py, f).into_any(),
            col_major(py, data, n, n).into_any(),
        ))
    }

    /// `df/dp` (n_states x n_params).
    fn param_jacobian<'py>(
        &self,
        py: Python<'py>,
        p: &Bound<'py, PyAny>,
        x: &Bound<'py, PyAny>,
        t: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (p, x) = (self.params_of(p)?, self.state_of(x, "x")?);
        let (n, k) = (x.len(), p.len());
        Ok(col_major(py, self.model.param_jacobian_dense(&p, &x, t), n, k).into_any())
    }

    /// The closed-form rest state of docs/physics.md section 6 (Newton's start).
    fn equilibrium_guess<'py>(
        &self,
        py: Python<'py>,
        p: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let p = self.params_of(p)?;
        let mut x = vec![0.0; self.model.n_states()];
        self.model.equilibrium_guess(&p, &mut x);
        Ok(array1(py, x).into_any())
    }

    /// Pressure (Pa) and volume (m^3) of every vessel at `x`.
    fn pv<'py>(
        &self,
        py: Python<'py>,
        p: &Bound<'py, PyAny>,
        x: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let (p, x) = (self.params_of(p)?, self.state_of(x, "x")?);
        let k = self.model.vessel_names().len();
        let (mut pr, mut v) = (vec![0.0; k], vec![0.0; k]);
        self.model.pv(&p, &x, &mut pr, &mut v);
        Ok((array1(py, pr).into_any(), array1(py, v).into_any()))
    }

    /// Stored energy (J) and the terms of its rate (W) at `x`.
    fn energy<'py>(
        &self,
        py: Python<'py>,
        p: &Bound<'py, PyAny>,
        x: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (p, x) = (self.params_of(p)?, self.state_of(x, "x")?);
        let d = PyDict::new(py);
        let pw = self.model.power(&p, &x);
        d.set_item("energy", self.model.energy(&p, &x))?;
        d.set_item("gas_mass", self.model.gas_mass(&p, &x))?;
        d.set_item("heat", pw.heat)?;
        d.set_item("boundary", pw.boundary)?;
        d.set_item("mechanical", pw.mechanical)?;
        Ok(d)
    }
}

/// The family and the registered models: name, aliases, summary.
#[pyfunction]
pub fn models<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
    let out = PyList::empty(py);
    for e in FAMILY {
        let d = PyDict::new(py);
        d.set_item("name", e.name)?;
        d.set_item("aliases", e.aliases.to_vec())?;
        d.set_item("summary", e.summary)?;
        d.set_item("registered", false)?;
        out.append(d)?;
    }
    for u in user_models::registered() {
        let d = PyDict::new(py);
        d.set_item("name", u.name)?;
        d.set_item("aliases", Vec::<String>::new())?;
        d.set_item("summary", u.summary)?;
        d.set_item("registered", true)?;
        out.append(d)?;
    }
    Ok(out)
}
