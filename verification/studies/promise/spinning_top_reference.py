#!/usr/bin/env python3
"""Independent reference for spinning_top.yaml: a rigid body about a fixed point, Euler's
equations I_o w' + w x I_o w = c x (R^T m g) in the body frame and the quaternion kinematics,
integrated by scipy's DOP853 at rtol 1e-13. Prints CSV: time, tip_x..tip_vz at the given times.

  spinning_top_reference.py [--t-end 1.0] [--dt 0.001]
"""
import argparse
import sys

import numpy as np
from scipy.integrate import solve_ivp

M, C, TIP = 0.5, np.array([0, 0, 0.04]), np.array([0.01, 0, 0.06])
I_C = np.diag([3.0e-4, 3.0e-4, 4.0e-4])
I_O = I_C + M * (C @ C * np.eye(3) - np.outer(C, C))
G = np.array([0, 0, -9.81])
THETA0, PSI_RATE, PHI_RATE = 0.5235987755982988, 2.0, 150.0


def quat_mat(p):
    e0, e1, e2, e3 = p
    return np.array([[e0*e0+e1*e1-e2*e2-e3*e3, 2*(e1*e2-e0*e3), 2*(e1*e3+e0*e2)],
                     [2*(e1*e2+e0*e3), e0*e0-e1*e1+e2*e2-e3*e3, 2*(e2*e3-e0*e1)],
                     [2*(e1*e3-e0*e2), 2*(e2*e3+e0*e1), e0*e0-e1*e1-e2*e2+e3*e3]])


def rhs(t, s):
    p, w = s[:4], s[4:]
    R = quat_mat(p)
    torque = np.cross(C, R.T @ (M * G))
    dw = np.linalg.solve(I_O, torque - np.cross(w, I_O @ w))
    e0, e1, e2, e3 = p
    # p' = 1/2 p * (0, w_body)
    dp = 0.5 * np.array([-e1*w[0]-e2*w[1]-e3*w[2], e0*w[0]+e2*w[2]-e3*w[1],
                         e0*w[1]+e3*w[0]-e1*w[2], e0*w[2]+e1*w[1]-e2*w[0]])
    return np.concatenate([dp, dw])


def initial_state():
    # ZXZ with psi = phi = 0: R = Rx(theta); body rates of (psi', theta', phi') = (2, 0, 150).
    th = THETA0
    p = np.array([np.cos(th / 2), np.sin(th / 2), 0, 0])
    w = np.array([PSI_RATE * np.sin(th) * 0.0, PSI_RATE * np.sin(th), PSI_RATE * np.cos(th) + PHI_RATE])
    return np.concatenate([p, w])


def samples(times):
    sol = solve_ivp(rhs, (0, times[-1]), initial_state(), method="DOP853", t_eval=times, rtol=float(__import__("os").environ.get("REF_RTOL", "1e-13")), atol=1e-16)
    out = []
    for k, t in enumerate(sol.t):
        p, w = sol.y[:4, k], sol.y[4:, k]
        p = p / np.linalg.norm(p)
        R = quat_mat(p)
        out.append([t, *(R @ TIP), *(R @ np.cross(w, TIP))])
    return np.array(out)


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--t-end", type=float, default=1.0)
    ap.add_argument("--dt", type=float, default=0.001)
    a = ap.parse_args()
    n = int(round(a.t_end / a.dt))
    s = samples(np.linspace(0, a.t_end, n + 1))
    sys.stdout.write("time,tip_x,tip_y,tip_z,tip_vx,tip_vy,tip_vz\n")
    for row in s:
        sys.stdout.write(",".join("%.17g" % v for v in row) + "\n")
