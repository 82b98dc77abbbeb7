"""Random optimizer configs through the real binary. Per member: profile --config C
--gaze-deg G --certificate D --out F; exit 0 => check F == 0, optimality == certificate.json,
mpscheck; exit 1/2 => one line, no F/D; never a panic; wall and CPU time recorded."""
import json, os, random, subprocess, sys, time, resource, shutil
B = '/work/targets/break-opt/release/gaze-lidar'
PRE = {'paper': dict(P=1e-3, lo=0.0, hi=1.25e-3, wmin=31.4159, wmax=628.3, fr=20),
       'vls128': dict(P=18e-6, lo=3.6e-6, hi=23.4e-6, wmin=31.4159, wmax=125.66, fr=10),
       'vlp16': dict(P=240e-6, lo=48e-6, hi=312e-6, wmin=31.4159, wmax=125.66, fr=10),
       'os1-128': dict(P=13e-6, lo=2.6e-6, hi=16.9e-6, wmin=31.4159, wmax=125.66, fr=10)}

def gen(rng):
    pre = rng.choice(list(PRE)); p = PRE[pre]
    L = ['bins = %d' % rng.choice([36, 37, 60, 72, 90, 120, 180, 216, 360, 500, 720]), '', '[lidar]', 'preset = "%s"' % pre,
         'power_accounting = "%s"' % rng.choice(['time', 'angle'])]
    lim = []
    if rng.random() < 0.4:
        lim.append('power_slew_w_per_deg_max = %r' % (p['P'] * rng.choice([0.002, 0.01, 0.05, 0.3])))
    acc = rng.random()
    accel = None
    if acc < 0.3: lim.append('spin_accel_rad_s2_max = "unlimited"')
    elif acc < 0.7:
        accel = rng.choice([100.0, 300.0, 1000.0, 3000.0]); lim.append('spin_accel_rad_s2_max = %r' % accel)
    if rng.random() < 0.3:
        lim.append('power_w_max = %r' % (p['P'] * rng.choice([1.1, 1.5, 2.0, 3.0])))
    L += ['', '[limits]'] + lim
    a = rng.random()
    if a < 0.33: ac = '{ model = "box", half_width_deg = %r }' % rng.choice([10.0, 30.0, 45.0, 90.0]); th = 0.5
    elif a < 0.66: ac = '{ model = "levi_e2", e2_deg = %r }' % rng.choice([2.3, 2.72, 5.0]); th = rng.choice([0.05, 0.0831, 0.2])
    else: ac = '{ model = "gaussian", sigma_deg = %r }' % rng.choice([10.0, 20.0, 40.0]); th = rng.choice([0.1, 0.5])
    L += ['', '[focus]', 'threshold = %r' % th, 'acuity = %s' % ac]
    lv = []
    if rng.random() < 0.4:
        k = rng.randint(2, 6); hi = p['hi']
        pw = sorted(set(round(rng.uniform(max(p['lo'], 0.1 * p['P']), hi), 12) for _ in range(k)))
        if rng.random() < 0.5: pw = sorted(set(pw + [p['P']]))
        lv.append('power_w = %r' % pw)
    if rng.random() < 0.25 and accel is None:
        k = rng.randint(2, 3)
        sp = sorted(round(rng.uniform(p['wmin'] * 1.05, p['wmax'] * 0.95), 6) for _ in range(k))
        if rng.random() < 0.5:
            w0 = 2 * 3.141592653589793 * p['fr']; sp = sorted(set([w0] + sp))
        lv.append('spin_rad_s = %r' % sp)
    if lv: L += ['', '[levels]'] + lv
    mode = rng.choice(['range', 'resolution', 'joint'])
    L += ['', '[objective]', 'mode = "%s"' % mode, 'kind = "%s"' % rng.choice(['sqrt', 'detection']),
          'range_weight = %r' % rng.choice([1.0, 0.5, 2.0]), 'resolution_weight = %r' % rng.choice([1.0, 0.5, 0.1])]
    if rng.random() < 0.3:
        L.append('priors = [{ start_deg = %r, width_deg = %r, weight = %r }]' % (rng.uniform(0, 360), rng.uniform(5, 90), rng.choice([0.2, 0.5, 1.0])))
    return '\n'.join(L) + '\n', round(rng.uniform(0, 360), 3)

def run(args, out):
    t0 = time.time(); r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    pr = subprocess.run(args, capture_output=True, text=True)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return pr, time.time() - t0, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)

def main(seed, count, outdir):
    rng = random.Random(seed); os.makedirs(outdir, exist_ok=True)
    log = open(os.path.join(outdir, 'log.jsonl'), 'a')
    for k in range(count):
        cfg, gaze = gen(rng)
        d = os.path.join(outdir, 'm%04d' % k); shutil.rmtree(d, ignore_errors=True); os.makedirs(d)
        cp = os.path.join(d, 'c.toml'); open(cp, 'w').write(cfg)
        F = os.path.join(d, 'p.json'); D = os.path.join(d, 'cert')
        pr, wall, cpu = run([B, 'profile', '--config', cp, '--gaze-deg', str(gaze), '--certificate', D, '--out', F], None)
        rec = dict(k=k, gaze=gaze, rc=pr.returncode, wall=round(wall, 3), cpu=round(cpu, 3), err=pr.stderr.strip()[-600:])
        issues = []
        if pr.returncode not in (0, 1, 2) or 'panick' in pr.stderr: issues.append('PANIC/odd rc')
        errlines = [l for l in pr.stderr.strip().split('\n') if l and 'warning' not in l]
        if pr.returncode == 0:
            c = subprocess.run([B, 'check', F], capture_output=True, text=True)
            if c.returncode != 0: issues.append('CHECK FAILED: ' + c.stdout[-300:] + c.stderr[-300:])
            prof = json.load(open(F)); o = prof.get('optimality')
            if not o: issues.append('no optimality block')
            elif not os.path.exists(os.path.join(D, 'certificate.json')): issues.append('no certificate')
            else:
                ce = json.load(open(os.path.join(D, 'certificate.json')))
                for key in ('objective', 'upper_bound', 'gap'):
                    if o[key] != ce[key]: issues.append('optimality.%s %r != cert %r' % (key, o[key], ce[key]))
                if o['upper_bound'] < o['objective']: issues.append('ub < objective')
                g = o.get('global')
                if g and g['upper_bound'] < g['objective']: issues.append('global ub < objective')
                rec['gap'] = o['gap']; rec['global'] = g
            if cpu > 2.0: issues.append('SLOW cpu %.2f' % cpu)
        else:
            if os.path.exists(F): issues.append('output file left on failure')
            if os.path.exists(D) and os.listdir(D): issues.append('cert dir populated on failure')
            if len(errlines) != 1: issues.append('not one error line: %d' % len(errlines))
        rec['issues'] = issues
        log.write(json.dumps(rec) + '\n'); log.flush()
        print(k, pr.returncode, '%.2fs' % wall, issues, (errlines[-1][:200] if pr.returncode else ''), flush=True)

if __name__ == '__main__':
    main(int(sys.argv[1]), int(sys.argv[2]), sys.argv[3])
