import json, math, sys
sys.path.insert(0, __import__('os').path.dirname(__file__))
import oracle as o
def model_pass(h, ch, a=7.0):
    # the checker's pass (geometry.rs doc): (a + w)/(R cos beta), w at the slant distance
    r, r0 = h['aperture_distance_mm'], h['origin_radius_mm']
    phi, eps = math.radians(ch['azimuth_offset_deg']), math.radians(ch['elevation_deg'])
    s = -r0*math.cos(phi) + math.sqrt(r*r - r0*r0*math.sin(phi)**2)
    psi = math.atan2(s*math.sin(phi), r0 + s*math.cos(phi))
    w = h['exit_diameter_mm'] + h['divergence_mrad']*1e-3*s/math.cos(eps)
    z = h.get('origin_height_mm',0) + s*math.tan(eps)
    return math.degrees((a + w)/(r*math.cos(phi-psi))), math.degrees(psi), z
for r0, phi, eps, exit_, div in [(58.63, 6.354, 0, 10, 3), (58.63, 30, 0, 10, 3), (15.806, 4.2, 0, 10, 3), (90, 45, 0, 10, 0), (90, 80, 0, 10, 0), (0, 0, 0, 10, 0), (0,0,0,20,0), (41.91,0,-15,10,3), (58.63,6.354,-25,10,3), (58.63, 60, 0, 10, 3), (0,0,60,10,0)]:
    h = {"cycle_s":1e-6,"origin_radius_mm":r0,"origin_height_mm":0,"exit_diameter_mm":exit_,"divergence_mrad":div,"aperture_distance_mm":100.0,
         "channels":[{"id":0,"elevation_deg":eps,"azimuth_offset_deg":phi,"slot_s":0}]}
    ch = h['channels'][0]
    mp, psi, z = model_pass(h, ch)
    out = []
    o.ORIENT['a'] = 7.0
    for m in ['normal', 'beam', 'radial']:
        o.ORIENT['mode'] = m
        iv = o.pass_interval(h, ch, psi, z, 7.0)
        out.append((iv[1]-iv[0]) / mp if iv else 0)
    print(f"r0={r0} phi={phi} eps={eps} exit={exit_} div={div}: model pass {mp:.4f} deg; true/model normal {out[0]:.5f} beam-disc {out[1]:.5f} radial-disc {out[2]:.5f}")
print("height scan")
import numpy as np
for r0, phi, eps, exit_, div in [(0,0,60,10,0),(58.63,30,40,10,3),(90,60,45,10,0),(90,80,10,10,0)]:
    h = {"cycle_s":1e-6,"origin_radius_mm":r0,"origin_height_mm":0,"exit_diameter_mm":exit_,"divergence_mrad":div,"aperture_distance_mm":100.0,
         "channels":[{"id":0,"elevation_deg":eps,"azimuth_offset_deg":phi,"slot_s":0}]}
    ch = h['channels'][0]
    mp, psi, z = model_pass(h, ch)
    for m in ['normal','beam']:
        o.ORIENT['mode'] = m
        best = (0, None)
        for dz in np.linspace(-30, 30, 41):
            iv = o.pass_interval(h, ch, psi, z + dz, 7.0)
            if iv and iv[1]-iv[0] > best[0]:
                best = (iv[1]-iv[0], dz)
        print(f"r0={r0} phi={phi} eps={eps}: {m} max width/model {best[0]/mp:.5f} at dz={best[1]}")
