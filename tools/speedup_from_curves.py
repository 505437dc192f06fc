#!/usr/bin/env python3
# tools/speedup_from_curves.py CSV METHOD BUDGET_SPP METHOD_MS PATHTRACE_MS_PER_SPP
# Equal-noise speed-up from a converge CSV's noise curves (load-free: noise against spp) and frame
# times measured interleaved (tools/interleaved_frame_times.sh): path tracing's spp to reach the method's noise at its
# budget (log-log interpolation, or error ~ spp^-1/2 past the last point, as convergence.cpp),
# times its ms per spp, over the method's ms.
import csv, sys, math
def curve(rows, method, col):
    return [(int(r['spp']), float(r[col])) for r in rows if r['method'] == method]
def spp_to_reach(pts, target):
    if pts[0][1] <= target: return pts[0][0], False
    for (sa, ea), (sb, eb) in zip(pts, pts[1:]):
        if eb > target: continue
        f = 1.0 if ea == eb else (math.log(target) - math.log(ea)) / (math.log(eb) - math.log(ea))
        return math.exp(math.log(sa) + f * (math.log(sb) - math.log(sa))), False
    s, e = pts[-1]
    return s * (e / target) ** 2, True
rows = list(csv.DictReader(open(sys.argv[1])))
method, budget, ob_ms, pt_ms_per_spp = sys.argv[2], int(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
for col in ['rmse_noise', 'rmse_trimmed_noise', 'mae_noise']:
    noise = dict(curve(rows, method, col))[budget]
    spp, extrap = spp_to_reach(curve(rows, 'pathtrace', col), noise)
    print(f"{method} {col}: noise {noise:.5f}, path tracing needs {spp:.1f} spp{' (extrap.)' if extrap else ''} = {spp*pt_ms_per_spp:.0f} ms -> speed-up {spp*pt_ms_per_spp/ob_ms:.2f}x")
