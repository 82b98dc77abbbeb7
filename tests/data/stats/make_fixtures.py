"""Reference numbers for src/sim/stats.rs, produced by scipy.stats.

Run: python tests/data/stats/make_fixtures.py > tests/data/stats/scipy_fixtures.json
(generated with scipy 1.17.1, numpy from the same venv). The Rust test
tests/sim_stats.rs reads the JSON; nothing here is copied into the crate.

Cases:
- wilcoxon: two-sided, zero_method="wilcox"; method="exact" when the non-zero
  differences are at most 50 and untied, else method="asymptotic" with
  correction=True (the crate's rule, stated in stats.rs).
- sign: scipy.stats.binomtest(k_positive, n_nonzero, 0.5), two-sided.
- rank_biserial: (R+ - R-)/(R+ + R-) from scipy.stats.rankdata of |d|.
- bootstrap: scipy.stats.bootstrap((x,), np.median, method="percentile",
  confidence_level=0.95, n_resamples=20000, random_state fixed); the crate
  draws other random numbers, so the test compares up to one order statistic.
- percentile: numpy.percentile (linear) of fixed samples.
"""
import json

import numpy as np
from scipy import stats


def wil_case(name, d):
    d = np.asarray(d, dtype=float)
    nz = d[d != 0]
    ranks = stats.rankdata(np.abs(nz))
    tied = len(np.unique(np.abs(nz))) < len(nz)
    rp = float(ranks[nz > 0].sum())
    rm = float(ranks[nz < 0].sum())
    if len(nz) <= 50 and not tied:
        method = "exact"
        res = stats.wilcoxon(d, zero_method="wilcox", method="exact")
    else:
        method = "normal"
        res = stats.wilcoxon(d, zero_method="wilcox", method="asymptotic", correction=True)
    kpos = int((d > 0).sum())
    n = int((d != 0).sum())
    sign_p = stats.binomtest(kpos, n, 0.5).pvalue
    return {
        "name": name,
        "d": d.tolist(),
        "n": n,
        "r_plus": rp,
        "r_minus": rm,
        "wilcoxon_method": method,
        "wilcoxon_p": float(res.pvalue),
        "sign_p": float(sign_p),
        "rank_biserial": (rp - rm) / (rp + rm),
        "median_difference": float(np.median(d)),
    }


rng = np.random.default_rng(20261127)
cases = []
# Exact: small, untied.
cases.append(wil_case("exact_n8", rng.normal(0.3, 1.0, 8).round(6)))
cases.append(wil_case("exact_n20_shifted", rng.normal(0.5, 1.0, 20).round(6)))
cases.append(wil_case("exact_n50", rng.normal(0.1, 1.0, 50).round(6)))
cases.append(wil_case("exact_with_zeros", np.concatenate([rng.normal(-0.4, 1.0, 15).round(6), [0.0, 0.0, 0.0]])))
# Normal: ties (simulator-like quantized TTAs, 0.05 s frames) and large n.
cases.append(wil_case("ties_n30", (rng.integers(-4, 7, 30) * 0.05).round(2)))
cases.append(wil_case("ties_n100_zeros", (rng.integers(-3, 4, 100) * 0.05).round(2)))
cases.append(wil_case("normal_n80", rng.normal(0.2, 1.0, 80).round(6)))
cases.append(wil_case("normal_n400", rng.normal(-0.05, 1.0, 400).round(6)))
cases.append(wil_case("bimodal_shift_n100", np.where(rng.random(100) < 0.3, 1.39, 0.0) + rng.normal(0, 0.01, 100).round(4)))

boot = []
for name, x in [
    ("normal_n41", rng.normal(5.0, 0.4, 41).round(4)),
    ("bimodal_n100", np.where(rng.random(100) < 0.6, 4.6, 5.97) + rng.normal(0, 0.02, 100).round(4)),
]:
    res = stats.bootstrap((x,), np.median, method="percentile", confidence_level=0.95,
                          n_resamples=20000, random_state=np.random.default_rng(1))
    boot.append({
        "name": name,
        "x": x.tolist(),
        "median": float(np.median(x)),
        "lo": float(res.confidence_interval.low),
        "hi": float(res.confidence_interval.high),
    })

pct = []
for x, q in [([1.0, 2.0, 3.0, 4.0, 5.0], 2.5), ([0.3, 0.7, 1.9, 2.2], 97.5),
             (sorted(rng.normal(0, 1, 2000).round(6).tolist()), 2.5),
             (sorted(rng.normal(0, 1, 2000).round(6).tolist()), 97.5)]:
    pct.append({"x": x, "q": q, "value": float(np.percentile(x, q))})

print(json.dumps({"scipy": __import__("scipy").__version__, "numpy": np.__version__,
                  "paired": cases, "bootstrap": boot, "percentile": pct}, indent=1))
