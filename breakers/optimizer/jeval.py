"""Independent model objective J (sqrt kind) of a profile, from the docs:
J = sum_i theta_i W_i (lamR sqrt(p_i/Pbar) [range/joint] + lamRho sqrt(r_i) [resolution/joint]),
W_i = deficit(ecc_i) + priors + eps + 1e-3 (ecc_i+180)/360, r_i = t_i 2pi/(theta_i T),
t_i = 2 theta_i/(w_s + w_e)."""
import json, math, sys

def wrap_signed(e):
    e = math.fmod(e, 360.0)
    if e > 180: e -= 360
    if e <= -180: e += 360
    return e

def value(acuity, e):
    e = wrap_signed(e); m = acuity['model']
    if m == 'box': return 1.0 if abs(e) <= acuity['half_width_deg'] else 0.0
    if m == 'levi_e2': return acuity['e2_deg'] / (abs(e) + acuity['e2_deg'])
    if m == 'gaussian': return math.exp(-e * e / (2 * acuity['sigma_deg'] ** 2))
    raise ValueError(m)

def deficit(acuity, e):
    pk = value(acuity, 0.0)
    return min(1.0, max(0.0, 1 - value(acuity, e) / pk))

def in_arc(start, width, c):
    s = start % 360.0
    return ((c - s) % 360.0) < width if width < 360 else True

def weights(n, gaze, acuity, priors=(), eps=1e-3):
    W = []
    for i in range(n):
        c = (i + 0.5) * 360.0 / n
        ecc = wrap_signed(c - gaze)
        pr = sum(p['weight'] for p in priors if in_arc(p['start_deg'], p['width_deg'], c))
        W.append(deficit(acuity, ecc) + pr + eps + 1e-3 * (ecc + 180) / 360)
    return W

def J(profile, acuity, mode, lamR=1.0, lamRho=1.0, priors=(), eps=1e-3, Pbar=None):
    b = profile['bins']; n = len(b); T = 1 / profile['frame_rate_hz']
    Pbar = Pbar or profile['average_power_w']
    W = weights(n, profile['gaze_deg'], acuity, priors, eps)
    tot = 0.0
    for i, bi in enumerate(b):
        th = math.radians(bi['width_deg'])
        t = 2 * th / (bi['spin_start_rad_s'] + bi['spin_end_rad_s'])
        r = t * 2 * math.pi / (th * T)
        v = 0.0
        if mode in ('range', 'joint'): v += lamR * math.sqrt(max(0, bi['power_w'] / Pbar))
        if mode in ('resolution', 'joint'): v += lamRho * math.sqrt(max(0, r))
        tot += th * W[i] * v
    return tot

if __name__ == '__main__':
    p = json.load(open(sys.argv[1])); cfg = json.loads(sys.argv[2])
    print(J(p, **cfg))
