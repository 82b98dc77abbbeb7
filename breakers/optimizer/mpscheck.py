"""Independent check of a --certificate DIR: parse problem.mps ourselves (free MPS),
solve with HiGHS (highspy) as LP and MILP, recompute objective/upper_bound from x,y
in exact Fractions, and compare with certificate.json."""
import sys, json
from fractions import Fraction as F
import highspy

def parse_mps(path):
    rows = {}; order = []; obj = None; sense = 'MIN'
    cols = {}; corder = []; ints = set(); rhs = {}; ranges = {}; bnds = {}
    sec = None; intmode = False
    for line in open(path):
        if not line.strip() or line.startswith('*'): continue
        if not line[0].isspace():
            t = line.split(); sec = t[0]
            if sec == 'OBJSENSE' and len(t) > 1: sense = t[1]
            continue
        t = line.split()
        if sec == 'OBJSENSE': sense = t[0]
        elif sec == 'ROWS':
            if t[0] == 'N': obj = t[1]
            else: rows[t[1]] = t[0]; order.append(t[1])
        elif sec == 'COLUMNS':
            if len(t) >= 3 and t[1] == "'MARKER'":
                intmode = (t[2] == "'INTORG'"); continue
            c = t[0]
            if c not in cols: cols[c] = {}; corder.append(c)
            if intmode: ints.add(c)
            for k in range(1, len(t), 2): cols[c][t[k]] = t[k+1]
        elif sec == 'RHS':
            for k in range(1, len(t), 2): rhs[t[k]] = t[k+1]
        elif sec == 'RANGES':
            for k in range(1, len(t), 2): ranges[t[k]] = t[k+1]
        elif sec == 'BOUNDS':
            typ, c = t[0], t[2]
            v = t[3] if len(t) > 3 else None
            lo, hi = bnds.get(c, (None, None))
            if typ == 'UP': hi = v
            elif typ == 'LO': lo = v
            elif typ == 'FX': lo = hi = v
            elif typ == 'FR': lo, hi = '-inf', 'inf'
            elif typ == 'MI': lo = '-inf'
            elif typ == 'PL': hi = 'inf'
            elif typ == 'BV': lo, hi = '0', '1'; ints.add(c)
            else: raise ValueError(typ)
            bnds[c] = (lo, hi)
    return dict(rows=rows, order=order, obj=obj, sense=sense, cols=cols, corder=corder,
                ints=ints, rhs=rhs, ranges=ranges, bnds=bnds)

def fr(s):
    if s in ('inf', '+inf', 'Infinity', '1e+30', '1e30'): return None
    return F(float(s))  # exact value of the double

def row_bounds(m, r):
    typ = m['rows'][r]; b = F(float(m['rhs'].get(r, '0')))
    if r in m['ranges']:
        R = F(float(m['ranges'][r]))
        if typ == 'E': return (b, b + R) if R >= 0 else (b + R, b)
        if typ == 'L': return (b - abs(R), b)
        if typ == 'G': return (b, b + abs(R))
    if typ == 'E': return (b, b)
    if typ == 'L': return (None, b)
    if typ == 'G': return (b, None)

def col_bounds(m, c):
    lo, hi = m['bnds'].get(c, (None, None))
    if c in m['ints'] and c not in m['bnds']: lo, hi = '0', '1'
    flo = F(0) if lo is None else (None if lo in ('-inf','-1e+30','-1e30') else F(float(lo)))
    fhi = None if hi is None or hi in ('inf','1e+30','1e30') else F(float(hi))
    return flo, fhi

def solve(path, integral):
    h = highspy.Highs(); h.setOptionValue('output_flag', False)
    h.readModel(path)
    if not integral:
        lp = h.getLp()
        # relax integrality
        n = lp.num_col_
        h.changeColsIntegrality(n, list(range(n)), [highspy.HighsVarType.kContinuous]*n) if n else None
    h.setOptionValue('mip_rel_gap', 0.0); h.setOptionValue('mip_abs_gap', 0.0)
    h.setOptionValue('time_limit', 120.0)
    h.run()
    st = h.getModelStatus()
    info = h.getInfo()
    return h.modelStatusToString(st), info.objective_function_value, getattr(info, 'mip_dual_bound', None)

def main(d):
    m = parse_mps(d + '/problem.mps'); cert = json.load(open(d + '/certificate.json'))
    x = [F(v) for v in cert['x']]; y = [F(v) for v in cert['y']]
    assert len(x) == len(m['corder']) and len(y) == len(m['order']), (len(x), len(m['corder']), len(y), len(m['order']))
    cidx = {c: j for j, c in enumerate(m['corder'])}
    c = [F(float(m['cols'][cn].get(m['obj'], '0'))) for cn in m['corder']]
    rows = {r: {} for r in m['order']}
    for cn in m['corder']:
        for r, v in m['cols'][cn].items():
            if r != m['obj']: rows[r][cidx[cn]] = F(float(v))
    sense = m['sense']
    # primal feasibility
    viol = []
    for j, cn in enumerate(m['corder']):
        lo, hi = col_bounds(m, cn)
        if (lo is not None and x[j] < lo) or (hi is not None and x[j] > hi): viol.append(('col', cn, float(x[j]), lo, hi))
        if cn in m['ints'] and x[j].denominator != 1: viol.append(('int', cn, float(x[j])))
    for r in m['order']:
        ax = sum(a * x[j] for j, a in rows[r].items()); lo, hi = row_bounds(m, r)
        if (lo is not None and ax < lo) or (hi is not None and ax > hi): viol.append(('row', r, float(ax), lo and float(lo), hi and float(hi)))
    obj = sum(ci * xi for ci, xi in zip(c, x))
    # dual bound (maximise): c^T x <= sum_r max(y lo, y hi) + sum_j max(d lo, d hi)
    d_ = list(c)
    for i, r in enumerate(m['order']):
        for j, a in rows[r].items(): d_[j] -= a * y[i]
    ub = F(0); inf = False
    for i, r in enumerate(m['order']):
        lo, hi = row_bounds(m, r); cand = []
        if y[i] == 0: continue
        for b in (lo, hi):
            if b is not None: cand.append(y[i] * b)
        # multiplier with infinite needed side counts as 0: per spec
        if lo is None or hi is None:
            need = hi if y[i] > 0 else lo
            if need is None: continue
            ub += y[i] * need; continue
        ub += max(cand)
    for j, cn in enumerate(m['corder']):
        lo, hi = col_bounds(m, cn)
        if d_[j] == 0: continue
        need = hi if d_[j] > 0 else lo
        if need is None: inf = True; continue
        ub += d_[j] * need
    print('dir', d, 'sense', sense, 'cols', len(x), 'rows', len(y), 'ints', len(m['ints']))
    print(' violations', len(viol), viol[:5])
    print(' objective exact == cert:', obj == F(cert['objective_exact']), float(obj), cert['objective'])
    print(' upper exact == cert:', (not inf) and ub == F(cert['upper_bound_exact']), float(ub) if not inf else 'inf', cert['upper_bound'])
    lp = solve(d + '/problem.mps', False); print(' HiGHS LP relaxation of MPS:', lp)
    if m['ints']:
        mip = solve(d + '/problem.mps', True); print(' HiGHS MILP of MPS:', mip)
        best = mip[1]
    else: best = lp[1]
    print(' HiGHS optimum - cert upper_bound = %.3e ; HiGHS optimum - cert objective = %.3e' % (best - cert['upper_bound'], best - cert['objective']))
    if best > cert['upper_bound'] * (1 + 1e-12) + 1e-12: print(' !!! HiGHS optimum ABOVE certified upper bound')

if __name__ == '__main__':
    for d in sys.argv[1:]: main(d)
