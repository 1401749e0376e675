#!/usr/bin/env python3
"""Growth of `mrslc compile` (all modes) with program size, and its fitted exponent.

Usage: scripts/compile-growth.py MRSLC [--chain] [SIZES...] (default sizes 125 250 500 1000 2000).
Writes generated programs of N independent coarse effects (each refining where its
fwidth is large, summed by the output), or with --chain a chain of N coarse effects
(each reads the one before; the first refines where its fwidth is large), under a
temporary directory, times one compile of each (wall time, CPU time and peak memory
from /usr/bin/time), and fits time = a * N^k by least squares on log-log, for the wall
time and for the CPU time (user + system: less disturbed by a loaded machine). Issue
59's target is k <= 1.2.
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

def chain(n):
    s = "in float3 normal;\nin float2 uv;\nuniform float t = 0.05;\n"
    s += "coarse effect float e0 {\n    e0 = saturate(normal.y);\n    if (fwidth(e0) > t) refine;\n}\n"
    for k in range(1, n):
        s += "coarse effect float e%d = e%d * 0.5 + uv.x * 0.25;\n" % (k, k - 1)
    return s + "fine out float4 color = float4(float3(e%d), 1.0);\n" % (n - 1)

def fit(points):
    """The slope of the least-squares line through (log n, log t)."""
    mx = sum(x for x, _ in points) / len(points)
    my = sum(y for _, y in points) / len(points)
    return sum((x - mx) * (y - my) for x, y in points) / sum((x - mx) ** 2 for x, _ in points)

def main():
    args = sys.argv[2:]
    make = chain if "--chain" in args else program
    sizes = [int(a) for a in args if a != "--chain"] or [125, 250, 500, 1000, 2000]
    mrslc, wall, cpu, work = sys.argv[1], [], [], tempfile.mkdtemp(prefix="mrsl-growth-")
    for n in sizes:
        src = os.path.join(work, "g%d.mrsl" % n)
        open(src, "w").write(make(n))
        out = os.path.join(work, "out%d" % n)
        r = subprocess.run(["/usr/bin/time", "-f", "%e %U %S %M", mrslc, "compile", src, "-o", out],
                           capture_output=True, text=True, check=True)
        secs, user, system, kb = r.stderr.strip().splitlines()[-1].split()
        busy = float(user) + float(system)
        size = sum(os.path.getsize(os.path.join(out, f)) for f in os.listdir(out) if f.endswith(".wgsl"))
        print("%6d effects: %7.2f s wall, %7.2f s CPU, %5d MB peak, %6.1f MB of WGSL"
              % (n, float(secs), busy, int(kb) // 1024, size / 1e6))
        wall.append((math.log(n), math.log(float(secs))))
        cpu.append((math.log(n), math.log(busy)))
    print("fitted exponent: %.2f (wall), %.2f (CPU)" % (fit(wall), fit(cpu)))

main()
