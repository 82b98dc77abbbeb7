"""Independent MILP (highspy) for range mode with hardware levels, sqrt kind, optional slew:
max sum_i theta W_i lamR sqrt(l_k/Pbar) z_ik  s.t. one level per bin, sum_i l_i <= N Pbar (1+1e-9),
|l_{i+1}-l_i| <= s * 360/N (cyclic). Compare with the binary's answer and optimality.global."""
import json, math, os, random, subprocess, sys
import numpy as np, highspy
sys.path.insert(0, os.path.dirname(__file__))
from jeval import J, weights
B = '/work/targets/break-opt/release/gaze-lidar'

def run(seed):
    r = random.Random(seed)
    N = r.choice([12, 16, 24]); P = 1e-3
    K = r.randint(2, 6); lv = sorted(set(round(r.uniform(0.05e-3, 1.25e-3), 9) for _ in range(K)))
    if r.random() < 0.5: lv = sorted(set(lv + [P]))
    slew = r.choice([None, None, 2e-5, 5e-5, 1e-4])
    ac = r.choice([{'model': 'box', 'half_width_deg': 30.0}, {'model': 'levi_e2', 'e2_deg': 2.72}, {'model': 'gaussian', 'sigma_deg': 20.0}])
    acct = r.choice(['angle', 'time']); gaze = round(r.uniform(0, 360), 2); lamR = r.choice([1.0, 2.0])
    priors = [] if r.random() < 0.5 else [{'start_deg': round(r.uniform(0, 360), 2), 'width_deg': round(r.uniform(10, 90), 2), 'weight': 0.5}]
    cfg = ['bins = %d' % N, '[lidar]', 'preset = "paper"', 'power_accounting = "%s"' % acct, '[limits]',
           'power_slew_w_per_deg_max = %s' % (repr(slew) if slew else '"unlimited"'),
           '[limits.eye_safety]', 'wavelength_nm = 1550.0', 'pulse_duration_s = 5e-9', 'beam_diameter_mm = 8.0',
           '[focus]', 'threshold = %s' % ('0.5' if ac['model'] == 'box' else '0.0831'),
           'acuity = { model = "%s", %s }' % (ac['model'], ', '.join('%s = %r' % (k, v) for k, v in ac.items() if k != 'model')),
           '[levels]', 'power_w = %r' % lv, '[objective]', 'mode = "range"', 'kind = "sqrt"', 'range_weight = %r' % lamR]
    if priors: cfg.append('priors = [{ start_deg = %r, width_deg = %r, weight = 0.5 }]' % (priors[0]['start_deg'], priors[0]['width_deg']))
    d = '/tmp/bo_lv'; os.makedirs(d, exist_ok=True); cp = '%s/l%d.toml' % (d, seed); open(cp, 'w').write('\n'.join(cfg) + '\n')
    out = '%s/l%d.json' % (d, seed)
    pr = subprocess.run([B, 'profile', '--config', cp, '--gaze-deg', str(gaze), '--out', out], capture_output=True, text=True)
    if pr.returncode != 0:
        return dict(seed=seed, rc=pr.returncode, err=pr.stderr.strip()[-250:], N=N, lv=lv, slew=slew)
    prof = json.load(open(out)); g = prof['optimality']['global']
    W = weights(N, gaze, ac, priors); th = 2 * math.pi / N
    h = highspy.Highs(); h.setOptionValue('output_flag', False); h.setOptionValue('mip_rel_gap', 0.0); h.setOptionValue('mip_abs_gap', 0.0)
    nz = N * len(lv); inf = highspy.kHighsInf
    cost = [th * W[i] * lamR * math.sqrt(l / P) for i in range(N) for l in lv]
    h.addVars(nz, [0.0] * nz, [1.0] * nz)
    h.changeColsCost(nz, list(range(nz)), cost)
    h.changeColsIntegrality(nz, list(range(nz)), [highspy.HighsVarType.kInteger] * nz)
    h.changeObjectiveSense(highspy.ObjSense.kMaximize)
    K = len(lv)
    for i in range(N):
        h.addRow(1.0, 1.0, K, [i * K + k for k in range(K)], [1.0] * K)
    h.addRow(-inf, N * P * (1 + 1e-9), nz, list(range(nz)), [l for i in range(N) for l in lv])
    if slew:
        lim = slew * 360.0 / N * (1 + 1e-9)
        for i in range(N):
            j = (i + 1) % N
            idx = [i * K + k for k in range(K)] + [j * K + k for k in range(K)]
            h.addRow(-lim, lim, 2 * K, idx, lv + [-l for l in lv])
    h.run()
    opt = h.getInfo().objective_function_value
    sol = h.getSolution().col_value
    const = sum(th * W[i] for i in range(N))  # resolution term at uniform spin (lamRho=1)
    # my optimum as a profile, checked
    cand = json.loads(json.dumps(prof)); cand.pop('optimality'); cand.pop('summary', None)
    for i in range(N):
        k = max(range(K), key=lambda k: sol[i * K + k]); cand['bins'][i]['power_w'] = lv[k]
    json.dump(cand, open('%s/l%d_ref.json' % (d, seed), 'w'))
    c = subprocess.run([B, 'check', '%s/l%d_ref.json' % (d, seed)], capture_output=True, text=True)
    Jref = J(cand, ac, 'joint', lamR, 1.0, priors); Jopt = J(prof, ac, 'joint', lamR, 1.0, priors)
    return dict(seed=seed, N=N, K=K, slew=slew, acct=acct, milp_opt_plus_const=opt + const, Jref=Jref, ref_check=c.returncode,
                Jopt=Jopt, gobj=g['objective'], gub=g['upper_bound'], ref_above_ub=Jref - g['upper_bound'], opt_short=Jref - Jopt)

if __name__ == '__main__':
    for s in range(int(sys.argv[1]), int(sys.argv[2])):
        print(json.dumps(run(s)), flush=True)
