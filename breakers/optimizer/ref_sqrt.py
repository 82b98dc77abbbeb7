"""Independent reference for the global bound, sqrt kind, continuous power and spin, no
acceleration/slew limits: maximise J = sum theta W_i (lamR sqrt(x_i) + lamRho sqrt(tau_i))
s.t. sum tau_i = N (frame), budget sum x_i <= N (angle) or sum tau_i x_i <= N (time), boxes.
Solved by multi-start SLSQP; the point is written as a profile, checked by `gaze-lidar check`,
scored by jeval.J and compared with optimality.global.upper_bound."""
import json, math, os, random, subprocess, sys, copy
import numpy as np
from scipy.optimize import minimize
sys.path.insert(0, os.path.dirname(__file__))
from jeval import J, weights
EYE1550 = os.environ.get('EYE1550') == '1'
B = '/work/targets/break-opt/release/gaze-lidar'

def optimize_ref(N, W, th, lamR, lamRho, xlo, xhi, tlo, thi, acct, mode, starts, rng):
    def f(z):
        x, t = z[:N], z[N:]
        v = 0
        if mode in ('range', 'joint'): v += lamR * np.sum(th * W * np.sqrt(np.maximum(x, 1e-300)))
        if mode in ('resolution', 'joint'): v += lamRho * np.sum(th * W * np.sqrt(np.maximum(t, 1e-300)))
        return -v
    cons = [{'type': 'eq', 'fun': lambda z: np.sum(z[N:]) - N}]
    if acct == 'angle': cons.append({'type': 'ineq', 'fun': lambda z: N - np.sum(z[:N])})
    else: cons.append({'type': 'ineq', 'fun': lambda z: N - np.sum(z[:N] * z[N:])})
    bx = [(xlo, xhi)] * N if mode != 'resolution' else [(1.0, 1.0)] * N
    bt = [(tlo, thi)] * N if mode != 'range' else [(1.0, 1.0)] * N
    best = None
    for s in starts:
        z0 = s if s is not None else np.concatenate([rng.uniform(xlo, min(xhi, 2), N), rng.uniform(tlo, min(thi, 2), N)])
        z0 = np.clip(z0, [b[0] for b in bx + bt], [b[1] for b in bx + bt])
        r = minimize(f, z0, method='SLSQP', bounds=bx + bt, constraints=cons, options=dict(maxiter=2000, ftol=1e-15))
        if best is None or r.fun < best.fun: best = r
    return best

def make_profile(template, x, tau, Pbar, T, N):
    p = copy.deepcopy(template); p.pop('optimality', None); p.pop('summary', None)
    bins = []
    for i in range(N):
        th = 2 * math.pi / N; t = tau[i] * T / N; w = th / t
        bins.append(dict(start_deg=template['bins'][i]['start_deg'], width_deg=template['bins'][i]['width_deg'],
                         power_w=x[i] * Pbar, spin_start_rad_s=w, spin_end_rad_s=w))
    p['bins'] = bins
    return p

def check(p, path):
    json.dump(p, open(path, 'w'))
    r = subprocess.run([B, 'check', path], capture_output=True, text=True)
    return r.returncode, (r.stdout + r.stderr).strip()[-400:]

def case(N, acct, mode, acuity, gaze, lamR=1.0, lamRho=1.0, priors=(), preset='paper', pmax=None, tag='c', rng=None):
    cfg = ['bins = %d' % N, '[lidar]', 'preset = "%s"' % preset, 'power_accounting = "%s"' % acct, '[limits]',
           'spin_accel_rad_s2_max = "unlimited"']
    if pmax: cfg.append('power_w_max = %r' % pmax)
    if EYE1550: cfg += ['[limits.eye_safety]', 'wavelength_nm = 1550.0', 'pulse_duration_s = 5e-9', 'beam_diameter_mm = 8.0']
    a = acuity
    acs = '{ model = "%s", %s }' % (a['model'], ', '.join('%s = %r' % (k, v) for k, v in a.items() if k != 'model'))
    cfg += ['[focus]', 'threshold = 0.5' if a['model'] == 'box' else 'threshold = 0.0831', 'acuity = %s' % acs,
            '[objective]', 'mode = "%s"' % mode, 'kind = "sqrt"', 'range_weight = %r' % lamR, 'resolution_weight = %r' % lamRho]
    if priors: cfg.append('priors = [%s]' % ', '.join('{ start_deg = %r, width_deg = %r, weight = %r }' % (p['start_deg'], p['width_deg'], p['weight']) for p in priors))
    d = '/tmp/bo_ref'; os.makedirs(d, exist_ok=True)
    cp = '%s/%s.toml' % (d, tag); open(cp, 'w').write('\n'.join(cfg) + '\n')
    out = '%s/%s.json' % (d, tag)
    r = subprocess.run([B, 'profile', '--config', cp, '--gaze-deg', str(gaze), '--out', out], capture_output=True, text=True)
    if r.returncode != 0: return dict(tag=tag, rc=r.returncode, err=r.stderr.strip()[-300:])
    prof = json.load(open(out)); g = prof['optimality']['global']
    Pbar = prof['average_power_w']; T = 1 / prof['frame_rate_hz']; L = prof['limits']
    xlo, xhi = L['power_w_min'] / Pbar, L['power_w_max'] / Pbar
    tlo = 2 * math.pi / (L['spin_rad_s_max'] * T); thi = 2 * math.pi / (L['spin_rad_s_min'] * T)
    W = np.array(weights(N, gaze, acuity, priors)); th = np.full(N, 2 * math.pi / N)
    # start from the optimizer's answer and random points
    x0 = np.array([b['power_w'] / Pbar for b in prof['bins']])
    t0 = np.array([(2 * th[i] / (b['spin_start_rad_s'] + b['spin_end_rad_s'])) * N / T for i, b in enumerate(prof['bins'])])
    starts = [np.concatenate([x0, t0])] + [None] * 6
    res = optimize_ref(N, W, th, lamR, lamRho, xlo, xhi, tlo, thi, acct, mode, starts, rng)
    x, t = res.x[:N].copy(), res.x[N:].copy()
    # make strictly feasible: scale powers down by 1e-9, renormalise tau to sum N
    t = t * N / t.sum(); x = np.clip(x * (1 - 1e-9), xlo, xhi)
    cand = make_profile(prof, x, t, Pbar, T, N)
    rc, msg = check(cand, '%s/%s_ref.json' % (d, tag))
    lam = 1.0
    if rc != 0:  # line search towards the optimizer's (certified) answer; the checker decides
        zo = np.concatenate([x0, t0]); zr = np.concatenate([x, t]); lo_, hi_ = 0.0, 1.0
        for _ in range(14):
            m = (lo_ + hi_) / 2; z = zo + m * (zr - zo); tt = z[N:] * N / z[N:].sum()
            c2 = make_profile(prof, z[:N], tt, Pbar, T, N)
            if check(c2, '%s/%s_ls.json' % (d, tag))[0] == 0: lo_ = m
            else: hi_ = m
        z = zo + lo_ * (zr - zo); x, t = z[:N], z[N:] * N / z[N:].sum(); lam = lo_
        cand = make_profile(prof, x, t, Pbar, T, N); rc, msg2 = check(cand, '%s/%s_ref.json' % (d, tag))
    Jref = J(cand, acuity, mode if mode != 'range' else 'joint', lamR, lamRho, priors) if mode == 'joint' else J(cand, acuity, 'joint', lamR, lamRho, priors)
    Jopt = J(prof, acuity, 'joint', lamR, lamRho, priors)
    return dict(tag=tag, N=N, acct=acct, mode=mode, gaze=gaze, opt_obj=g['objective'], my_J_of_opt=Jopt, ub=g['upper_bound'],
                ref_J=Jref, ref_check=rc, ref_msg=msg if rc else '', above_ub=(Jref - g['upper_bound']) if rc == 0 else None,
                ref_minus_opt=Jref - g['objective'], lam=lam)

if __name__ == '__main__':
    rng = np.random.default_rng(int(sys.argv[1]) if len(sys.argv) > 1 else 0)
    pr = random.Random(int(sys.argv[1]) if len(sys.argv) > 1 else 0)
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 10
    for k in range(n):
        N = pr.choice([12, 18, 24, 36]); acct = pr.choice(['angle', 'time']); mode = pr.choice(['range', 'resolution', 'joint'])
        ac = pr.choice([{'model': 'box', 'half_width_deg': 30.0}, {'model': 'levi_e2', 'e2_deg': 2.72}, {'model': 'gaussian', 'sigma_deg': 20.0}])
        priors = [] if pr.random() < 0.6 else [{'start_deg': pr.uniform(0, 360), 'width_deg': pr.uniform(10, 90), 'weight': 0.5}]
        res = case(N, acct, mode, ac, round(pr.uniform(0, 360), 2), lamR=pr.choice([1.0, 2.0]), lamRho=pr.choice([1.0, 0.5]), priors=priors,
                   pmax=pr.choice([None, 1.5e-3, 3e-3]), tag='r%d_%d' % (int(sys.argv[1]) if len(sys.argv) > 1 else 0, k), rng=rng)
        print(json.dumps(res), flush=True)
