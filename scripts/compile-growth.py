#!/usr/bin/env python3
"""Growth of `mrslc compile` (all modes) with program size, and its fitted exponent.

Usage: scripts/compile-growth.py MRSLC [SIZES...] (default sizes 125 250 500 1000 2000).
Writes generated programs of N independent coarse effects (each refining where its
fwidth is large, summed by the output) under a temporary directory, times one compile
of each (wall time and peak memory from /usr/bin/time), and fits time = a * N^k by
least squares on log-log. Issue 59's target is k <= 1.2.
"""
import math, os, subprocess, sys, tempfile

def program(n):
    def total(t):
        return t[0] if len(t) == 1 else "(%s + %s)" % (total(t[:len(t) // 2]), total(t[len(t) // 2:]))
    s = "in float3 normal;\nin float2 uv;\nuniform float t = 0.05;\nuniform float3 light = float3(0.0, 1.0, 0.0);\n\n"
    for k in range(n):
        s += ("coarse effect float e%d {\n    e%d = saturate(dot(normal, light) * %.2f + uv.x * %.3f);\n"
              "    if (fwidth(e%d) > t) refine;\n}\n") % (k, k, 0.25 * (k % 7 + 1), k / n, k)
    return s + "fine out float4 color = float4(float3(%s), 1.0);\n" % total(["e%d" % k for k in range(n)])

def main():
    mrslc, sizes = sys.argv[1], [int(a) for a in sys.argv[2:]] or [125, 250, 500, 1000, 2000]
    points, work = [], tempfile.mkdtemp(prefix="mrsl-growth-")
    for n in sizes:
        src = os.path.join(work, "g%d.mrsl" % n)
        open(src, "w").write(program(n))
        out = os.path.join(work, "out%d" % n)
        r = subprocess.run(["/usr/bin/time", "-f", "%e %M", mrslc, "compile", src, "-o", out],
                           capture_output=True, text=True, check=True)
        secs, kb = r.stderr.strip().splitlines()[-1].split()
        size = sum(os.path.getsize(os.path.join(out, f)) for f in os.listdir(out) if f.endswith(".wgsl"))
        print("%6d effects: %7.2f s, %5d MB peak, %6.1f MB of WGSL" % (n, float(secs), int(kb) // 1024, size / 1e6))
        points.append((math.log(n), math.log(float(secs))))
    mx = sum(x for x, _ in points) / len(points)
    my = sum(y for _, y in points) / len(points)
    k = sum((x - mx) * (y - my) for x, y in points) / sum((x - mx) ** 2 for x, _ in points)
    print("fitted exponent: %.2f" % k)

main()
