import math
def hit(head, ch, surface, R=100.0):
    r0 = head["origin_radius_mm"]; e = math.radians(ch["elevation_deg"]); f = math.radians(ch["azimuth_offset_deg"])
    ux, uy, uz = math.cos(e) * math.cos(f), math.cos(e) * math.sin(f), math.sin(e)
    if surface == "cylinder":
        a = ux * ux + uy * uy
    else:
        a = 1.0
    b = 2 * r0 * ux; c = r0 * r0 - R * R
    t = (-b + math.sqrt(b * b - 4 * a * c)) / (2 * a)
    z = t * uz  # above the crossing point / C
    if surface == "cylinder":
        z += head.get("origin_height_mm", 0.0)
    return z
