import json, sys, math
def prof(bins, f, lam, tau, beam, frame_rate=None, acc="time"):
    # bins: list of (width_deg, power_w, w0, w1)
    out=[]; s=0.0; T=0.0; E=0.0
    for (w,p,w0,w1) in bins:
        out.append(dict(start_deg=s,width_deg=w,power_w=p,spin_start_rad_s=w0,spin_end_rad_s=w1))
        d=2*math.radians(w)/(w0+w1); T+=d; E+=p*d; s+=w
    pmax=max(b[1] for b in bins); smin=min(min(b[2],b[3]) for b in bins); smax=max(max(b[2],b[3]) for b in bins)
    return dict(format="gaze-lidar/profile@1", frame_rate_hz=1.0/T, pulse_rate_hz=f, average_power_w=E/T*1.000001,
        power_accounting=acc, gaze_deg=None,
        limits=dict(power_w_min=0.0,power_w_max=pmax,spin_rad_s_min=smin,spin_rad_s_max=smax,spin_accel_rad_s2_max=None,
                    power_slew_w_per_deg_max=None, eye_safety=dict(wavelength_nm=lam,pulse_duration_s=tau,beam_diameter_mm=beam)),
        bins=out)
