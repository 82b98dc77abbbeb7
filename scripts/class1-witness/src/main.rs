// Independent brute-force Class 1 evaluator: a witness search. Uses no gaze-lidar code.
// Model: aperture at azimuth psi, 100 mm from the scan centre; beam overlaps it
// while |beta - psi| <= (D_a(T) + D_b)/2/100 mm; the whole pulse energy P/f counts.
// Pulses t_k = phi + k/f. Rules: (1) every pulse (and every greedy T_i group in
// 700-1050 nm) <= AEL(tau) * C5(N), N = most pulses (groups) in any 10 s window;
// (2) every window [t, t+T), T <= 100 s: energy <= AEL(T), taken as
// max_{i<=j} E(i..j) / inf_{T in [t_j - t_i + tau, 100]} AEL(T).
use std::f64::consts::PI;

#[derive(Clone, Copy, PartialEq, Debug)]
enum Band {
    Nir,
    Ir1400,
    Ir1500,
}

struct Laser {
    band: Band,
    c4: f64,
    tau: f64,
    f: f64,
    beam_mm: f64,
}

fn c4(l: f64) -> f64 {
    if (700.0..=1050.0).contains(&l) {
        10f64.powf(0.002 * (l - 700.0))
    } else {
        1.0
    }
}

impl Laser {
    // Table 3 written from the standard's rows; at a row edge the smaller value.
    fn ael(&self, t: f64) -> f64 {
        let c = self.c4;
        let mut v = f64::INFINITY;
        match self.band {
            Band::Nir => {
                if t <= 5e-6 {
                    v = v.min(7.7e-8 * c);
                }
                if t >= 5e-6 && t <= 10.0 {
                    v = v.min(7e-4 * c * t.powf(0.75));
                }
                if t >= 10.0 {
                    v = v.min(3.9e-4 * c * t);
                }
            }
            Band::Ir1400 => {
                if t <= 1e-3 {
                    v = v.min(8e-4);
                }
                if t >= 1e-3 && t <= 0.35 {
                    v = v.min(4.4e-3 * t.powf(0.25));
                }
                if t >= 0.35 && t <= 10.0 {
                    v = v.min(1e-2 * t);
                }
                if t >= 10.0 {
                    v = v.min(1e-2 * t);
                }
            }
            Band::Ir1500 => {
                if t <= 0.35 {
                    v = v.min(8e-3);
                }
                if t >= 0.35 && t <= 10.0 {
                    v = v.min(1.8e-2 * t.powf(0.75));
                }
                if t >= 10.0 {
                    v = v.min(1e-2 * t);
                }
            }
        }
        v
    }
    fn edges(&self) -> &'static [f64] {
        match self.band {
            Band::Nir => &[5e-6, 10.0],
            Band::Ir1400 => &[1e-3, 0.35, 10.0],
            Band::Ir1500 => &[0.35, 10.0],
        }
    }
    // inf of AEL over [lo, 100]
    fn ael_inf(&self, lo: f64) -> f64 {
        let lo = lo.max(self.tau);
        let mut v = self.ael(lo);
        for &e in self.edges() {
            if e > lo && e <= 100.0 {
                v = v.min(self.ael(e));
            }
        }
        v
    }
    fn ti(&self) -> f64 {
        match self.band {
            Band::Nir => 5e-6,
            Band::Ir1400 => 1e-3,
            Band::Ir1500 => 10.0,
        }
    }
    fn c5(&self, n: f64) -> f64 {
        if self.band != Band::Nir || self.tau > self.ti() || n <= 600.0 {
            1.0
        } else {
            (5.0 * n.powf(-0.25)).clamp(0.4, 1.0)
        }
    }
    // Table 10 aperture (mm) for an exposure of duration t
    fn aperture_mm(&self, t: f64) -> f64 {
        match self.band {
            Band::Nir => 7.0,
            _ => {
                if t <= 0.35 {
                    1.0
                } else if t < 10.0 {
                    1.5 * t.powf(0.375)
                } else {
                    3.5
                }
            }
        }
    }
}

#[derive(Clone, Copy)]
struct Bin {
    s: f64,
    w: f64,
    p: f64,
    w0: f64,
    a: f64,
    dwell: f64,
    t0: f64,
}

struct Prof {
    bins: Vec<Bin>,
    tf: f64,
}

impl Prof {
    fn time_at(&self, th: f64) -> f64 {
        // th in [0, 2pi)
        let i = match self.bins.iter().rposition(|b| b.s <= th) {
            Some(i) => i,
            None => 0,
        };
        let b = &self.bins[i];
        let x = (th - b.s).max(0.0).min(b.w);
        let u = if b.a.abs() < 1e-300 {
            x / b.w0
        } else {
            ((b.w0 * b.w0 + 2.0 * b.a * x).max(0.0).sqrt() - b.w0) / b.a
        };
        b.t0 + u.min(b.dwell)
    }
    fn power_at_time(&self, t: f64) -> (f64, f64) {
        let t = t.rem_euclid(self.tf);
        let i = match self.bins.iter().rposition(|b| b.t0 <= t) {
            Some(i) => i,
            None => 0,
        };
        let b = &self.bins[i];
        let u = (t - b.t0).max(0.0);
        let th = b.s + b.w0 * u + 0.5 * b.a * u * u;
        (b.p, th)
    }
}

fn load(path: &str) -> (Prof, Laser) {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let f = v["pulse_rate_hz"].as_f64().unwrap();
    let es = &v["limits"]["eye_safety"];
    let lam = es["wavelength_nm"].as_f64().unwrap();
    let band = if (700.0..=1050.0).contains(&lam) {
        Band::Nir
    } else if (1400.0..1500.0).contains(&lam) {
        Band::Ir1400
    } else {
        Band::Ir1500
    };
    let laser = Laser {
        band,
        c4: c4(lam),
        tau: es["pulse_duration_s"].as_f64().unwrap(),
        f,
        beam_mm: es["beam_diameter_mm"].as_f64().unwrap(),
    };
    let mut bins = Vec::new();
    let mut t0 = 0.0;
    for b in v["bins"].as_array().unwrap() {
        let s = b["start_deg"].as_f64().unwrap().to_radians();
        let w = b["width_deg"].as_f64().unwrap().to_radians();
        let w0 = b["spin_start_rad_s"].as_f64().unwrap();
        let w1 = b["spin_end_rad_s"].as_f64().unwrap();
        let a = (w1 * w1 - w0 * w0) / (2.0 * w);
        let dwell = 2.0 * w / (w0 + w1);
        bins.push(Bin {
            s,
            w,
            p: b["power_w"].as_f64().unwrap(),
            w0,
            a,
            dwell,
            t0,
        });
        t0 += dwell;
    }
    (Prof { bins, tf: t0 }, laser)
}

struct Res {
    r1: f64,
    r2: f64,
    t2: f64,
    n: usize,
}

// Pulses entering for aperture psi, phase phi, over [0, horizon]. Aperture mm ap.
fn pulses(
    p: &Prof,
    l: &Laser,
    psi: f64,
    phi: f64,
    ap_mm: f64,
    horizon: f64,
    cap: usize,
) -> Vec<(f64, f64)> {
    let h = ((ap_mm + l.beam_mm) / 100.0 / 2.0).min(PI);
    let delta = 1.0 / l.f;
    let mut out = Vec::new();
    let (tin, dur) = if h >= PI {
        (0.0, p.tf)
    } else {
        let a = (psi - h).rem_euclid(2.0 * PI);
        let b = (psi + h).rem_euclid(2.0 * PI);
        let ti = p.time_at(a);
        let to = p.time_at(b);
        (ti, (to - ti).rem_euclid(p.tf))
    };
    let nfr = (horizon / p.tf).ceil() as i64 + 1;
    for j in -1..nfr {
        let s = j as f64 * p.tf + tin;
        let e = if h >= PI {
            s + p.tf * (1.0 - 1e-15)
        } else {
            s + dur
        };
        let k0 = ((s - phi) / delta).ceil() as i64;
        let k1 = ((e - phi) / delta).floor() as i64;
        for k in k0..=k1 {
            let t = phi + k as f64 * delta;
            if t < 0.0 || t > horizon {
                continue;
            }
            let (pw, _) = p.power_at_time(t);
            if pw > 0.0 {
                out.push((t, pw / l.f));
            }
            if out.len() > cap {
                return out;
            }
        }
    }
    out
}

fn eval(p: &Prof, l: &Laser, psi: f64, phi: f64, cap: usize) -> Res {
    // Rule 2 with the largest aperture for T>0.35 s and 1 mm below for IR: do two passes
    let mut r2 = 0.0f64;
    let mut t2 = 0.0;
    let mut r1 = 0.0f64;
    let mut n = 0;
    let aps: Vec<(f64, f64, f64)> = match l.band {
        Band::Nir => vec![(7.0, 0.0, 100.0)],
        _ => vec![(1.0, 0.0, 0.35), (3.5, 10.0, 100.0)],
    };
    // plus 0.35..10 s band with aperture 1.5 t^0.375: evaluate with per-length aperture via grid of apertures
    let mut bands = aps.clone();
    if l.band != Band::Nir {
        for k in 0..6 {
            let t0 = 0.35 * (10.0f64 / 0.35).powf(k as f64 / 6.0);
            let t1 = 0.35 * (10.0f64 / 0.35).powf((k + 1) as f64 / 6.0);
            bands.push((
                l.aperture_mm(t1.min(9.999999)).max(l.aperture_mm(t0)),
                t0,
                t1,
            ));
        }
    }
    for (ap, tlo, thi) in bands {
        let v = pulses(p, l, psi, phi, ap, 100.0 + 2.0 * p.tf.min(100.0), cap);
        n = n.max(v.len());
        let m = v.len();
        let mut pre = vec![0.0; m + 1];
        for i in 0..m {
            pre[i + 1] = pre[i] + v[i].1;
        }
        for i in 0..m {
            let etail = pre[m] - pre[i];
            let _ = etail;
            for j in i..m {
                if v[j].0 - v[i].0 > 1.5 * p.tf {
                    break;
                }
                let lmin = v[j].0 - v[i].0 + l.tau;
                if lmin > thi {
                    break;
                }
                let e = pre[j + 1] - pre[i];
                // window length in [max(lmin,tlo), thi] for this aperture
                let lo = lmin.max(tlo);
                let mut a = l.ael(lo.max(l.tau));
                for &ed in l.edges() {
                    if ed > lo && ed <= thi {
                        a = a.min(l.ael(ed));
                    }
                }
                if thi > lo {
                    a = a.min(l.ael(thi));
                } // AEL rises, kept for edges only
                let r = e / a;
                if r > r2 {
                    r2 = r;
                    t2 = lmin;
                }
            }
        }
        {
            let mut ts: Vec<f64> = vec![10.0, 100.0, 10.0 * (1.0 - 1e-12), 0.35, 1e-3];
            let nf = (100.0 / p.tf).floor() as i64;
            let n10 = (10.0 / p.tf).floor() as i64;
            for k in [1, 2, 3, n10 - 1, n10, n10 + 1, nf - 1, nf, nf + 1] {
                if k >= 1 {
                    for d in [0.0, 1e-9, -1e-9, 0.5 * p.tf] {
                        ts.push(k as f64 * p.tf + d);
                    }
                }
            }
            for &e in l.edges() {
                ts.push(e);
                ts.push(e * (1.0 - 1e-12));
            }
            for &t in &ts {
                if t < tlo || t > thi || t > 100.0 {
                    continue;
                }
                let mut jj = 0usize;
                let mut best = 0.0f64;
                for i in 0..m {
                    if jj < i {
                        jj = i;
                    }
                    while jj < m && v[jj].0 + l.tau - v[i].0 <= t {
                        jj += 1;
                    }
                    let e = pre[jj] - pre[i];
                    if e > best {
                        best = e;
                    }
                }
                let r = best / l.ael(t.max(l.tau));
                if r > r2 {
                    r2 = r;
                    t2 = t;
                }
            }
        }
        if tlo == 0.0 && (l.band == Band::Nir || ap == 1.0) {
            // Rule 1 with this aperture (pulse durations are short)
            let ti = l.ti();
            let mut nmax = 0usize;
            let mut jj = 0;
            for i in 0..m {
                while jj < m && v[jj].0 - v[i].0 <= 10.0 {
                    jj += 1;
                }
                nmax = nmax.max(jj - i);
            }
            let emax = v.iter().map(|x| x.1).fold(0.0, f64::max);
            if std::env::var("DBG").is_ok() {
                eprintln!("nmax {} emax {:e} m {}", nmax, emax, m);
            }
            r1 = r1.max(emax / (l.ael(l.tau) * l.c5(nmax as f64)));
            if l.band == Band::Nir && l.tau <= ti {
                // greedy groups from the first pulse, closed [t, t+Ti], restarting each pass (gap > Ti)
                let mut groups: Vec<(f64, f64, usize)> = Vec::new();
                let mut i = 0;
                while i < m {
                    let t0 = v[i].0;
                    let mut e = 0.0;
                    let mut c = 0;
                    while i < m && v[i].0 - t0 <= ti {
                        e += v[i].1;
                        i += 1;
                        c += 1;
                    }
                    groups.push((t0, e, c));
                }
                let mut ng = 0usize;
                let mut jj = 0;
                for i in 0..groups.len() {
                    while jj < groups.len() && groups[jj].0 - groups[i].0 <= 10.0 {
                        jj += 1;
                    }
                    ng = ng.max(jj - i);
                }
                let eg = groups
                    .iter()
                    .filter(|x| x.2 >= 2)
                    .map(|x| x.1)
                    .fold(0.0, f64::max);
                r1 = r1.max(eg / (l.ael(ti) * l.c5(ng as f64)));
            }
        }
    }
    Res { r1, r2, t2, n }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (p, l) = load(&args[1]);
    let npsi: usize = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(360);
    let nphi: usize = args.get(3).map(|s| s.parse().unwrap()).unwrap_or(8);
    let cap: usize = args.get(4).map(|s| s.parse().unwrap()).unwrap_or(20000);
    let mut psis: Vec<f64> = (0..npsi)
        .map(|k| 2.0 * PI * k as f64 / npsi as f64)
        .collect();
    let hmax = (7.0f64.max(3.5) + l.beam_mm) / 200.0;
    for b in &p.bins {
        for h in [hmax, (1.0 + l.beam_mm) / 200.0, (3.5 + l.beam_mm) / 200.0] {
            for d in [-h, h, 0.0] {
                psis.push((b.s + d).rem_euclid(2.0 * PI));
                psis.push((b.s + d + 1e-12).rem_euclid(2.0 * PI));
                psis.push((b.s + d - 1e-12).rem_euclid(2.0 * PI));
            }
        }
    }
    if let Some(extra) = std::env::var("PSI_DEG").ok() {
        for s in extra.split(',') {
            psis.push(s.parse::<f64>().unwrap().to_radians());
        }
    }
    let delta = 1.0 / l.f;
    let mut best = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut maxn = 0;
    for &psi in &psis {
        for k in 0..nphi {
            let phi = delta * (k as f64 + 0.5) / nphi as f64;
            let r = eval(&p, &l, psi, phi, cap);
            maxn = maxn.max(r.n);
            let m = r.r1.max(r.r2);
            if m > best.0 {
                best = (m, r.r1, r.r2, r.t2, psi.to_degrees(), phi);
            }
        }
    }
    println!("oracle ratio {:.9} r1 {:.9} r2 {:.9} window {:.6e} psi {:.6} phi {:.3e} tf {:.6e} maxpulses {}", best.0, best.1, best.2, best.3, best.4, best.5, p.tf, maxn);
}
