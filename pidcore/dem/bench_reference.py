"""A deliberately plain all-pairs DEM kernel: the machine's yardstick for ``pidcore bench dem``.

Issue 11 states its speed targets against "an independent straightforward all-pairs kernel"
(2.5 x 10^7 particle-steps/s on the issue author's machine for the resting bed). Absolute
particle-steps/s differ by a factor of ~2-3 between machines, so the benchmark times this
kernel on the same bed, in the same process, and reports our kernel's speed as a ratio to it.

It is written independently of :mod:`pidcore.dem.kernel` and :mod:`pidcore.dem.contact` on
purpose (a yardstick that shared their code would move with them): every pair and every wall
is tested every step (no neighbour list), the normal force is Hertz + Tsuji damping without
attraction, friction is regularised Coulomb without a spring (no contact history), the walls
move rigidly along z, and nothing is tallied. No simulation of pidcore uses it.

API: :func:`all_pairs_reference`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy")
def all_pairs_reference(pos: np.ndarray, vel: np.ndarray, omg: np.ndarray,
                        wall_normals: np.ndarray, wall_offsets: np.ndarray, radius: float,
                        mass: float, inertia: float, pair_law: np.ndarray,
                        wall_law: np.ndarray, gravity: float, dt: float, n_steps: int,
                        omega: float, accel_amp: float, v_reg: float) -> None:
    """Advance ``pos``, ``vel``, ``omg`` ((3, K, N), SI) by ``n_steps`` in place.

    ``pair_law`` and ``wall_law`` are (k_n [N/m^1.5], c_n [N s/m^1.25], mu): f_n = k_n
    delta^1.5 + c_n delta^0.25 ddelta/dt (>= 0), |f_t| = mu f_n against the slip of the
    contact points, scaled down linearly below ``v_reg`` [m/s]. The walls (inward unit
    normals ``wall_normals`` (W, 3), offsets [m]) move along z by -(a/w^2) sin(w t)
    (``omega`` w [rad/s], ``accel_amp`` a [m/s^2]; ``omega`` 0: at rest). Velocity Verlet;
    each call starts from gravity alone, without the contact forces of the state it is given
    (exact from a start without contacts; the bench times calls of many steps).
    """
    n_cells = pos.shape[1]
    n_part = pos.shape[2]
    n_walls = wall_normals.shape[0]
    force = np.zeros((3, n_part))
    torque = np.zeros((3, n_part))
    contact_2 = 4.0 * radius * radius
    pair_k, pair_c, pair_mu = pair_law[0], pair_law[1], pair_law[2]
    wall_k, wall_c, wall_mu = wall_law[0], wall_law[1], wall_law[2]
    for c in range(n_cells):
        x = pos[:, c, :].copy()
        v = vel[:, c, :].copy()
        w = omg[:, c, :].copy()
        force[:] = 0.0
        torque[:] = 0.0
        for i in range(n_part):
            force[2, i] = -mass * gravity
        for s in range(n_steps):
            for i in range(n_part):
                for k in range(3):
                    v[k, i] += 0.5 * dt * force[k, i] / mass
                    w[k, i] += 0.5 * dt * torque[k, i] / inertia
                    x[k, i] += dt * v[k, i]
                    force[k, i] = 0.0
                    torque[k, i] = 0.0
                force[2, i] = -mass * gravity
            lift = 0.0
            lift_speed = 0.0
            if omega > 0.0:
                t = (s + 1) * dt
                lift = -accel_amp / (omega * omega) * math.sin(omega * t)
                lift_speed = -accel_amp / omega * math.cos(omega * t)
            for i in range(n_part):
                for m in range(n_walls):
                    gap = (wall_normals[m, 0] * x[0, i] + wall_normals[m, 1] * x[1, i]
                           + wall_normals[m, 2] * (x[2, i] - lift) + wall_offsets[m])
                    if gap < radius:
                        overlap = radius - gap
                        fx, fy, fz, mx, my, mz = _contact(
                            -wall_normals[m, 0], -wall_normals[m, 1], -wall_normals[m, 2],
                            overlap, radius - overlap, v[0, i], v[1, i], v[2, i] - lift_speed,
                            w[0, i], w[1, i], w[2, i], wall_k, wall_c, wall_mu, v_reg)
                        _add(force, torque, i, fx, fy, fz, mx, my, mz)
                for j in range(i + 1, n_part):
                    dx = x[0, j] - x[0, i]
                    dy = x[1, j] - x[1, i]
                    dz = x[2, j] - x[2, i]
                    d2 = dx * dx + dy * dy + dz * dz
                    if d2 < contact_2:
                        d = math.sqrt(d2)
                        overlap = 2.0 * radius - d
                        fx, fy, fz, mx, my, mz = _contact(
                            dx / d, dy / d, dz / d, overlap, radius - 0.5 * overlap,
                            v[0, i] - v[0, j], v[1, i] - v[1, j], v[2, i] - v[2, j],
                            w[0, i] + w[0, j], w[1, i] + w[1, j], w[2, i] + w[2, j],
                            pair_k, pair_c, pair_mu, v_reg)
                        # the partner: the opposite force, the same friction torque
                        _add(force, torque, i, fx, fy, fz, mx, my, mz)
                        _add(force, torque, j, -fx, -fy, -fz, mx, my, mz)
            for i in range(n_part):
                for k in range(3):
                    v[k, i] += 0.5 * dt * force[k, i] / mass
                    w[k, i] += 0.5 * dt * torque[k, i] / inertia
        pos[:, c, :] = x
        vel[:, c, :] = v
        omg[:, c, :] = w


@njit(cache=True, inline="always")
def _contact(nx, ny, nz, overlap, arm, rvx, rvy, rvz, sx, sy, sz, k_n, c_n, mu, v_reg):
    """Force on the first body (normal ``n`` towards the partner, relative velocity ``rv``,
    ``s`` the angular velocity that moves the contact point) and the torque of its friction
    about the first body's centre (``arm`` from it to the contact point): (f, m), N, N m."""
    approach = rvx * nx + rvy * ny + rvz * nz
    root = math.sqrt(overlap)
    f_n = k_n * overlap * root + c_n * math.sqrt(root) * approach
    if f_n < 0.0:
        f_n = 0.0
    # slip of the contact points: relative velocity plus rotation, tangent part only
    tx = rvx + arm * (sy * nz - sz * ny) - approach * nx
    ty = rvy + arm * (sz * nx - sx * nz) - approach * ny
    tz = rvz + arm * (sx * ny - sy * nx) - approach * nz
    slip = math.sqrt(tx * tx + ty * ty + tz * tz)
    gx = 0.0
    gy = 0.0
    gz = 0.0
    if slip > 0.0:
        f_t = mu * f_n
        if slip < v_reg:
            f_t *= slip / v_reg
        gx = -f_t * tx / slip
        gy = -f_t * ty / slip
        gz = -f_t * tz / slip
    return (-f_n * nx + gx, -f_n * ny + gy, -f_n * nz + gz,
            arm * (ny * gz - nz * gy), arm * (nz * gx - nx * gz), arm * (nx * gy - ny * gx))


@njit(cache=True, inline="always")
def _add(force, torque, i, fx, fy, fz, mx, my, mz):
    """Add a force and a torque to particle ``i``."""
    force[0, i] += fx
    force[1, i] += fy
    force[2, i] += fz
    torque[0, i] += mx
    torque[1, i] += my
    torque[2, i] += mz
