#!/usr/bin/env python3
"""Writes the 5-axis CL files of the post's tests (tests/data/post/*.cl): four kinds of move
that a joint program interpolated row by row would leave. Run from anywhere; deterministic."""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def axis(tilt_deg, azimuth_deg):
    t, a = math.radians(tilt_deg), math.radians(azimuth_deg)
    return (math.sin(t) * math.cos(a), math.sin(t) * math.sin(a), math.cos(t))


def goto(p, a=None):
    if a is None:
        return "GOTO/%.4f,%.4f,%.4f" % p
    return "GOTO/%.4f,%.4f,%.4f,%.6f,%.6f,%.6f" % (p + a)


def write(name, comment, body):
    lines = ["$$ tests/data/post/%s: %s" % (name, comment), "$$ written by tests/data/post/make.py",
             "UNITS/MM", "MULTAX/ON", "LOADTL/1", "FROM/0.0000,0.0000,150.0000,0.000000,0.000000,1.000000"]
    lines += body + ["FINI"]
    with open(os.path.join(HERE, name), "w") as f:
        f.write("\n".join(lines) + "\n")


# A swarf ring: radius 60 at z = 20, the tool leaning outwards by 15 to 30 deg, 6 deg per block.
ring = ["RAPID", goto((60.0, 0.0, 60.0), axis(15, 0)), "FEDRAT/MMPM,1200.0"]
for k in range(61):
    psi = 6.0 * k
    tilt = 22.5 - 7.5 * math.cos(math.radians(2 * psi))
    ring.append(goto((60 * math.cos(math.radians(psi)), 60 * math.sin(math.radians(psi)), 20.0),
                     axis(tilt, psi)))
write("ring.cl", "a swarf ring, tilt 15-30 deg, 6 deg per block", ring)

# A pass 1 deg past the table normal: the axis's azimuth turns half a turn while its tilt stays
# near 1 deg; the tip moves 40 mm.
normal = ["RAPID", goto((-20.0, 0.0, 60.0), axis(5, 180)), "FEDRAT/MMPM,900.0"]
for k in range(41):
    t = -1.0 + 2.0 * k / 40
    tilt = math.hypot(t * 5.0, 1.0)
    azimuth = math.degrees(math.atan2(1.0, t * 5.0)) + 90.0
    normal.append(goto((-20.0 + k, 0.0, 30.0), axis(tilt, azimuth)))
write("normal.cl", "a pass 1 deg past the table normal", normal)

# Four 160 mm moves, each changing the tilt by up to 50 deg.
corners = [((-80.0, -40.0, 20.0), (5, 0)), ((80.0, -40.0, 20.0), (45, 0)),
           ((80.0, 40.0, 30.0), (10, 90)), ((-80.0, 40.0, 20.0), (40, 180)),
           ((-80.0, -40.0, 25.0), (-10, 90))]
longm = ["RAPID", goto((-80.0, -40.0, 60.0), axis(5, 0)), "FEDRAT/MMPM,2000.0"]
for p, (t, a) in corners:
    longm.append(goto(p, axis(t, a)))
write("long.cl", "four 160 mm moves, each changing the tilt by up to 50 deg", longm)

# A 3+2 pocket: the axis fixed at 20 deg, a contour of lines and CIRCLE arcs in the tilted plane.
a = axis(20, 30)
pocket = ["RAPID", goto((0.0, -30.0, 60.0), a), "FEDRAT/MMPM,1500.0", goto((0.0, -30.0, 30.0), a),
          goto((30.0, -30.0, 30.0), a),
          "CIRCLE/30.0000,0.0000,30.0000,0.000000,0.000000,1.000000,30.0000",
          goto((30.0, 30.0, 30.0), a), goto((-30.0, 30.0, 30.0), a),
          "CIRCLE/-30.0000,0.0000,30.0000,0.000000,0.000000,1.000000,30.0000",
          goto((-30.0, -30.0, 30.0), a), goto((0.0, -30.0, 30.0), a),
          "RAPID", goto((0.0, -30.0, 60.0), a)]
write("pocket.cl", "a 3+2 pocket at 20 deg with CIRCLE arcs", pocket)
