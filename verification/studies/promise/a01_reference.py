#!/usr/bin/env python3
"""Exact solution of A01 (verification/iftomm/scenes/A01_simple_pendulum.yaml): released at rest
with the link horizontal, phi(t) = 2 asin(k sn(K - w0 t; k)) from the bottom, k = sin(pi / 4).
Prints CSV: time, x_P1, y_P1, vx_P1, vy_P1.   a01_reference.py [--t-end 10] [--dt 0.01]"""
import argparse
import sys

import numpy as np
from scipy.special import ellipj, ellipk

ap = argparse.ArgumentParser()
ap.add_argument("--t-end", type=float, default=10.0)
ap.add_argument("--dt", type=float, default=0.01)
a = ap.parse_args()
g, L = 9.81, 1.0
k = np.sin(np.pi / 4)
m = k * k
w0 = np.sqrt(g / L)
K = ellipk(m)
t = np.linspace(0, a.t_end, int(round(a.t_end / a.dt)) + 1)
sn, cn, dn, _ = ellipj(K - w0 * t, m)
# angle from the downward vertical; the scene's link starts along +x (angle pi/2 from the bottom)
th = 2 * np.arcsin(k * sn)
thd = 2 * k * cn * dn * (-w0) / np.sqrt(1 - (k * sn) ** 2)
x, y = L * np.sin(th), -L * np.cos(th)
vx, vy = L * np.cos(th) * thd, L * np.sin(th) * thd
sys.stdout.write("time,x_P1,y_P1,vx_P1,vy_P1\n")
for row in zip(t, x, y, vx, vy):
    sys.stdout.write(",".join("%.17g" % v for v in row) + "\n")
