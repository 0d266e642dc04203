#!/usr/bin/python3
"""Plots the random-match experiment (thesis section 2.3, figure 2.8): average relative vote of
random point sets against the binomial model, per reference model.

    TEST_TMPDIR=/tmp/rv build/host-release/tests/hashing/hashing_test \
        --gtest_filter='RandomMatches.*'
    tools/plots/random_votes.py /tmp/rv/random_votes.csv docs/images/random-votes.png
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    rows = list(csv.reader(open(sys.argv[1])))
    models = []
    for r in rows:
        if r[1] not in models:
            models.append(r[1])
    fig, ax = plt.subplots(figsize=(7, 4.5), dpi=100)
    for i, m in enumerate(models):
        pts = [(int(r[0]), float(r[2]), float(r[3])) for r in rows if r[1] == m]
        colour = "C%d" % i
        ax.plot([p[0] for p in pts], [p[2] for p in pts], "-", color=colour, label=m + " (model)")
        ax.plot([p[0] for p in pts], [p[1] for p in pts], "o", color=colour)
    ax.set_xlabel("random scene points S (100 x 100 x 70 mm, sigma 5 mm)")
    ax.set_ylabel("average best relative vote")
    ax.set_title("Random matches: simulation (dots) and binomial model (lines)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(sys.argv[2])


if __name__ == "__main__":
    main()
