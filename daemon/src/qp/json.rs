//! JSON export and import of [`QpProblem`]s, so recorded controller QPs can be replayed by
//! tests, benchmarks and other solvers.
//!
//! Format (one problem): `{"n", "P", "q", "A_eq", "b_eq", "C", "l", "u", "x_min", "x_max"}` with
//! matrices as arrays of rows (dense, active rows only). JSON has no infinity, so an absent bound
//! is written as `null`: `null` in `l`/`x_min` means `-∞`, in `u`/`x_max` means `+∞`.

use serde_json::{Value, json};

use super::QpProblem;

/// A recorded problem could not be read; the message names the field and index.
#[derive(Debug, thiserror::Error)]
#[error("bad QP JSON: {0}")]
pub struct QpJsonError(String);

/// Writes the active part of `problem` as dense JSON (see the module docs for the format).
pub fn export_json(problem: &QpProblem) -> Value {
    let rows = |m: nalgebra::DMatrixView<'_, f64>| -> Vec<Vec<f64>> {
        (0..m.nrows())
            .map(|i| m.row(i).iter().copied().collect())
            .collect()
    };
    let vec = |v: nalgebra::DVectorView<'_, f64>| -> Vec<f64> { v.iter().copied().collect() };
    let bound = |v: nalgebra::DVectorView<'_, f64>| -> Vec<Option<f64>> {
        v.iter().map(|x| x.is_finite().then_some(*x)).collect()
    };
    json!({
        "n": problem.n(),
        "P": rows(problem.p()),
        "q": vec(problem.q()),
        "A_eq": rows(problem.a_eq()),
        "b_eq": vec(problem.b_eq()),
        "C": rows(problem.c()),
        "l": bound(problem.l()),
        "u": bound(problem.u()),
        "x_min": bound(problem.x_min()),
        "x_max": bound(problem.x_max()),
    })
}

/// Reads one problem written by [`export_json`]; capacities equal the active sizes.
pub fn problem_from_json(value: &Value) -> Result<QpProblem, QpJsonError> {
    let p = matrix(value, "P")?;
    let n = p.len();
    let a_eq = matrix(value, "A_eq")?;
    let c = matrix(value, "C")?;
    let mut problem = QpProblem::new(n, a_eq.len(), c.len());
    let parts = problem.parts_mut();
    fill_rows("P", &p, n, parts.p)?;
    fill_rows("A_eq", &a_eq, n, parts.a_eq)?;
    fill_rows("C", &c, n, parts.c)?;
    fill_vec(value, "q", n, None, parts.q)?;
    fill_vec(value, "b_eq", a_eq.len(), None, parts.b_eq)?;
    fill_vec(value, "l", c.len(), Some(f64::NEG_INFINITY), parts.l)?;
    fill_vec(value, "u", c.len(), Some(f64::INFINITY), parts.u)?;
    fill_vec(value, "x_min", n, Some(f64::NEG_INFINITY), parts.x_min)?;
    fill_vec(value, "x_max", n, Some(f64::INFINITY), parts.x_max)?;
    Ok(problem)
}

/// Reads a recording: a single problem, an array of problems, or `{"problems": [...]}`.
pub fn problems_from_json(value: &Value) -> Result<Vec<QpProblem>, QpJsonError> {
    let list = match value {
        Value::Array(list) => list,
        Value::Object(map) => match map.get("problems") {
            Some(Value::Array(list)) => list,
            Some(_) => return Err(QpJsonError("\"problems\" is not an array".into())),
            None => return problem_from_json(value).map(|p| vec![p]),
        },
        _ => {
            return Err(QpJsonError(
                "expected a problem object or an array of problems".into(),
            ));
        }
    };
    list.iter()
        .enumerate()
        .map(|(k, v)| {
            problem_from_json(v).map_err(|e| QpJsonError(format!("problem {k}: {}", e.0)))
        })
        .collect()
}

fn field<'a>(value: &'a Value, name: &str) -> Result<&'a Vec<Value>, QpJsonError> {
    value
        .get(name)
        .ok_or_else(|| QpJsonError(format!("missing field \"{name}\"")))?
        .as_array()
        .ok_or_else(|| QpJsonError(format!("\"{name}\" is not an array")))
}

fn matrix<'a>(value: &'a Value, name: &str) -> Result<Vec<&'a Vec<Value>>, QpJsonError> {
    field(value, name)?
        .iter()
        .enumerate()
        .map(|(i, r)| {
            r.as_array()
                .ok_or_else(|| QpJsonError(format!("\"{name}\"[{i}] is not an array")))
        })
        .collect()
}

fn number(name: &str, index: &str, v: &Value, null_as: Option<f64>) -> Result<f64, QpJsonError> {
    match (v, null_as) {
        (Value::Null, Some(inf)) => Ok(inf),
        _ => v
            .as_f64()
            .ok_or_else(|| QpJsonError(format!("\"{name}\"{index} is not a number: {v}"))),
    }
}

fn fill_rows(
    name: &str,
    rows: &[&Vec<Value>],
    n: usize,
    mut dst: nalgebra::DMatrixViewMut<'_, f64>,
) -> Result<(), QpJsonError> {
    for (i, row) in rows.iter().enumerate() {
        if row.len() != n {
            return Err(QpJsonError(format!(
                "\"{name}\"[{i}] has {} entries, expected n = {n}",
                row.len()
            )));
        }
        for (j, v) in row.iter().enumerate() {
            dst[(i, j)] = number(name, &format!("[{i}][{j}]"), v, None)?;
        }
    }
    Ok(())
}

fn fill_vec(
    value: &Value,
    name: &str,
    len: usize,
    null_as: Option<f64>,
    mut dst: nalgebra::DVectorViewMut<'_, f64>,
) -> Result<(), QpJsonError> {
    let list = field(value, name)?;
    if list.len() != len {
        return Err(QpJsonError(format!(
            "\"{name}\" has {} entries, expected {len}",
            list.len()
        )));
    }
    for (i, v) in list.iter().enumerate() {
        dst[i] = number(name, &format!("[{i}]"), v, null_as)?;
    }
    Ok(())
}
