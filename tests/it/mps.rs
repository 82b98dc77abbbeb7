//! The exported certificate read from the outside: a plain free-MPS reader
//! and the certificate's figures recomputed in rationals (shared by the
//! certificate and family tests).
#![allow(dead_code)]

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{Signed, Zero};
use std::collections::HashMap;

pub fn q(v: f64) -> BigRational {
    BigRational::from_float(v).expect("finite")
}

pub fn parse_rational(s: &str) -> BigRational {
    let (n, d) = s.split_once('/').expect("p/q");
    BigRational::new(n.parse::<BigInt>().unwrap(), d.parse::<BigInt>().unwrap())
}

/// A plain free-MPS reader (the subset HiGHS's reader and ours share:
/// OBJSENSE, N/L/G/E rows, integer markers, RHS, RANGES, LO/UP/FX/MI/PL).
pub struct Mps {
    pub maximise: bool,
    pub cost: Vec<f64>,
    pub lo: Vec<f64>,
    pub hi: Vec<f64>,
    pub integer: Vec<bool>,
    pub rows: Vec<MpsRow>,
}

/// (kind, coefficients, rhs, range)
pub type MpsRow = (char, Vec<(usize, f64)>, f64, Option<f64>);

pub fn read_mps(text: &str) -> Mps {
    let mut m = Mps {
        maximise: false,
        cost: vec![],
        lo: vec![],
        hi: vec![],
        integer: vec![],
        rows: vec![],
    };
    let mut row_ix: HashMap<String, usize> = HashMap::new();
    let mut col_ix: HashMap<String, usize> = HashMap::new();
    let mut obj_name = String::new();
    let mut section = String::new();
    let mut int_mode = false;
    for line in text.lines() {
        if line.trim().is_empty() {
            continue;
        }
        if !line.starts_with(' ') {
            section = line.split_whitespace().next().unwrap().to_owned();
            continue;
        }
        let f: Vec<&str> = line.split_whitespace().collect();
        match section.as_str() {
            "OBJSENSE" => m.maximise = f[0] == "MAX",
            "ROWS" => {
                let kind = f[0].chars().next().unwrap();
                if kind == 'N' {
                    obj_name = f[1].to_owned();
                } else {
                    row_ix.insert(f[1].to_owned(), m.rows.len());
                    m.rows.push((kind, vec![], 0.0, None));
                }
            }
            "COLUMNS" => {
                if f[1] == "'MARKER'" {
                    int_mode = f[2] == "'INTORG'";
                    continue;
                }
                let j = *col_ix.entry(f[0].to_owned()).or_insert_with(|| {
                    m.cost.push(0.0);
                    m.lo.push(0.0);
                    m.hi.push(f64::INFINITY);
                    m.integer.push(int_mode);
                    m.cost.len() - 1
                });
                for pair in f[1..].chunks(2) {
                    let v: f64 = pair[1].parse().unwrap();
                    if pair[0] == obj_name {
                        m.cost[j] = v;
                    } else {
                        m.rows[row_ix[pair[0]]].1.push((j, v));
                    }
                }
            }
            "RHS" => {
                for pair in f[1..].chunks(2) {
                    m.rows[row_ix[pair[0]]].2 = pair[1].parse().unwrap();
                }
            }
            "RANGES" => {
                for pair in f[1..].chunks(2) {
                    m.rows[row_ix[pair[0]]].3 = Some(pair[1].parse().unwrap());
                }
            }
            "BOUNDS" => {
                let j = col_ix[f[2]];
                match f[0] {
                    "LO" => m.lo[j] = f[3].parse().unwrap(),
                    "UP" => m.hi[j] = f[3].parse().unwrap(),
                    "FX" => {
                        m.lo[j] = f[3].parse().unwrap();
                        m.hi[j] = m.lo[j];
                    }
                    "MI" => m.lo[j] = f64::NEG_INFINITY,
                    "PL" => m.hi[j] = f64::INFINITY,
                    other => panic!("bound type {other}"),
                }
            }
            other => panic!("section {other}"),
        }
    }
    m
}

impl Mps {
    /// Row interval per the MPS rules.
    pub fn interval(&self, r: usize) -> (f64, f64) {
        let (kind, _, rhs, range) = &self.rows[r];
        match (kind, range) {
            ('L', None) => (f64::NEG_INFINITY, *rhs),
            ('G', None) => (*rhs, f64::INFINITY),
            ('E', None) => (*rhs, *rhs),
            ('L', Some(w)) => (rhs - w.abs(), *rhs),
            ('G', Some(w)) => (*rhs, rhs + w.abs()),
            ('E', Some(w)) if *w >= 0.0 => (*rhs, rhs + w),
            ('E', Some(w)) => (rhs + w, *rhs),
            _ => (f64::NEG_INFINITY, f64::INFINITY),
        }
    }
}

/// The certificate's figures, recomputed here: (primal feasible, cᵀx, bound).
pub fn exact_figures(m: &Mps, x: &[f64], y: &[f64]) -> (bool, BigRational, Option<BigRational>) {
    let n = m.cost.len();
    assert_eq!(x.len(), n, "x has one value per MPS column");
    assert_eq!(y.len(), m.rows.len(), "y has one value per MPS row");
    let xq: Vec<BigRational> = x.iter().map(|&v| q(v)).collect();
    let mut feasible = true;
    for (j, &xj) in x.iter().enumerate() {
        feasible &= m.lo[j] <= xj && xj <= m.hi[j];
        feasible &= !m.integer[j] || xj.fract() == 0.0;
    }
    let mut d: Vec<BigRational> = m.cost.iter().map(|&c| q(c)).collect();
    let mut bound = Some(BigRational::zero());
    let sup = |a: &BigRational, lo: f64, hi: f64| -> Option<BigRational> {
        if a.is_zero() {
            Some(BigRational::zero())
        } else if a.is_positive() {
            hi.is_finite().then(|| a * q(hi))
        } else {
            lo.is_finite().then(|| a * q(lo))
        }
    };
    for (r, row) in m.rows.iter().enumerate() {
        let (lo, hi) = m.interval(r);
        let ax = row
            .1
            .iter()
            .fold(BigRational::zero(), |s, &(j, a)| s + q(a) * &xq[j]);
        feasible &= (!lo.is_finite() || ax >= q(lo)) && (!hi.is_finite() || ax <= q(hi));
        // The certificate's rule: a multiplier on an infinite side counts as 0.
        let yr = y[r];
        if yr == 0.0 || (yr > 0.0 && !hi.is_finite()) || (yr < 0.0 && !lo.is_finite()) {
            continue;
        }
        let yq = q(yr);
        for &(j, a) in &row.1 {
            d[j] -= &yq * q(a);
        }
        bound = bound.and_then(|b| sup(&yq, lo, hi).map(|s| b + s));
    }
    for (j, dj) in d.iter().enumerate() {
        bound = bound.and_then(|b| sup(dj, m.lo[j], m.hi[j]).map(|s| b + s));
    }
    let obj = (0..n).fold(BigRational::zero(), |s, j| s + q(m.cost[j]) * &xq[j]);
    (feasible, obj, bound)
}
