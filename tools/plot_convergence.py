#!/usr/bin/python3
"""Plots speed against error from `obscura converge` (one job: CSV in, PNG out).

Usage: plot_convergence.py CONVERGENCE.csv OUT.png TITLE [CONVERGENCE.json]
Three log-log panels over GPU time: RMSE against the converged image of the same method (noise),
the same noise without the 0.1 % worst pixels (a firefly shows as the gap between the two), and
RMSE against converged path tracing (bias + noise), one curve per method. With the summary JSON,
the references' own noise (converge's "reference_noise") as dashed lines in the noise panels: a
curve that flattens onto one measures its reference, not the method. Uses Debian's
python3-matplotlib, hence /usr/bin/python3.
"""
import csv
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) not in (4, 5):
        sys.exit(__doc__)
    path, out, title = sys.argv[1:4]
    floors = {}
    if len(sys.argv) == 5:
        with open(sys.argv[4]) as f:
            floors = json.load(f).get("reference_noise", {})
    curves = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            curves.setdefault(row["method"], []).append(row)
    fig, axes = plt.subplots(1, 3, figsize=(17, 4.8), constrained_layout=True)
    for method, rows in curves.items():
        t = [float(r["gpu_ms"]) for r in rows]
        style = dict(marker="o", markersize=3, linewidth=1.5 if method == "pathtrace" else 1.0,
                     color="black" if method == "pathtrace" else None)
        axes[0].loglog(t, [float(r["rmse_noise"]) for r in rows], label=method, **style)
        axes[1].loglog(t, [float(r["rmse_trimmed_noise"]) for r in rows], label=method, **style)
        axes[2].loglog(t, [float(r["rmse_vs_pathtrace"]) for r in rows], label=method, **style)
        for r in rows:  # the paper's budget: 8 primary samples
            if method == "obscurance" and r["spp"] == "8":  # the defaults: 8 + 2 rays per hit
                for ax, key in ((axes[0], "rmse_noise"), (axes[1], "rmse_trimmed_noise"), (axes[2], "rmse_vs_pathtrace")):
                    ax.annotate("64+16 rays/px", (float(r["gpu_ms"]), float(r[key])), fontsize=8,
                                xytext=(6, 6), textcoords="offset points")
    for name, own in floors.items():
        for ax, key in ((axes[0], "rmse"), (axes[1], "rmse_trimmed")):
            ax.axhline(own[key], linestyle="--", linewidth=0.8, color="black" if name == "pathtrace" else "grey",
                       label=f"{name} reference's own noise")
    axes[0].set_title(f"{title}: noise (RMSE vs same method converged)")
    axes[1].set_title(f"{title}: noise without the worst 0.1 % of pixels")
    axes[2].set_title(f"{title}: error vs converged path tracing")
    for ax in axes:
        ax.set_xlabel("GPU time per image (ms)")
        ax.set_ylabel("RMSE (linear radiance)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
