"""Numba time-stepping kernel: all cells, a chunk of steps, no Python objects inside.

State is structure-of-arrays: ``pos[0]`` is x of every particle of every cell (shape (K, N)),
``pos[1]`` y, ``pos[2]`` z; likewise ``vel``, ``omg`` (angular velocity), ``frc`` and ``trq``
(force and torque of the last evaluation, kept between chunks). Cells are independent and are
advanced in parallel (``prange``); each cell's arithmetic is serial and free of random numbers,
so the result does not depend on the thread count.

Integrator: velocity Verlet (kick-drift-kick). Velocity-dependent forces (damping, friction)
use the predicted full-step velocity v_pred = v(t-dt) + dt F(t-dt)/m (second order; LIGGGHTS
uses the half-step velocity, first order). The dissipation is tallied after the second kick
with the full-step velocity v(t) that this step's force acts on: then sum F(t).v(t) dt is the
kinetic energy change to second order and the energy balance closes to ~0.2-0.6 % at 10-12
steps per contact (with the half-step velocity it missed ~3 %). The walls move rigidly with
the cell: u(t) = -(a/w^2) sin(w t) along the drive axis, wall velocity -(a/w) cos(w t).

Energy tallies per cell and cycle (index ``[cell, cycle, k]``):
  0 work of the walls on the particles, sum f_wall_on_particle . v_wall dt
  1 dissipated by normal damping, sum f_damping * delta_dot(t) * dt
  2 dissipated by friction, sum -f_t . v_t(t) dt
with the full-step velocities v(t) after the second kick (see above). The force law makes
both non-negative with the predicted velocity it uses; with v(t) an increment could only turn
negative if other contacts reversed the motion within one step (tests check the totals).
Samples: sum over the sample interval of the drive-axis component of the force the walls
exert on the particles (divide by ``sample_every`` for the interval mean).

Friction (Eq. 5): f_t = -mu |f_n| v_t/|v_t|, scaled linearly below ``v_reg`` and capped at
m_t |v_t| / (2 dt) (m_t: effective tangential mass of the contact): the cap removes at most half
the slip per step, so at the slide-to-stick transition the slip decays geometrically instead of
chattering around zero, and friction never reverses the slip nor injects energy.

Status per cell: 0 ok; 1 overlap above ``max_overlap_fraction * r``; 2 a particle centre left
the cell; 3 non-finite state. ``fail_step`` holds the step where it happened.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

STATUS_OK = 0
STATUS_OVERLAP = 1
STATUS_ESCAPED = 2
STATUS_NONFINITE = 3
N_TALLIES = 3


@njit(cache=True, parallel=True)
def advance_cells(pos, vel, omg, frc, trq, wall_n, wall_d,
                  radius, mass, inertia,
                  k_pp, c_pp, mu_pp, mt_pp, k_pw, c_pw, mu_pw, mt_pw,
                  v_reg, clip_attraction, gravity,
                  dt, step0, n_steps, omega, accel_amp, drive_axis,
                  steps_per_cycle, sample_every, max_overlap_fraction,
                  tally, samples, status, fail_step):
    n_cells = pos.shape[1]
    n_part = pos.shape[2]
    n_walls = wall_n.shape[0]
    inv_m = 1.0 / mass
    inv_i = 1.0 / inertia
    two_r = 2.0 * radius
    max_overlap = max_overlap_fraction * radius
    for c in prange(n_cells):
        if status[c] != STATUS_OK:
            continue
        vp = np.empty((3, n_part))  # predicted full-step velocities (see module docstring)
        wp = np.empty((3, n_part))
        max_contacts = n_walls * n_part + n_part * (n_part - 1) // 2
        c_idx = np.empty((2, max_contacts), dtype=np.int64)  # i, j (j < 0: wall)
        c_val = np.empty((8, max_contacts))  # n (3), arm, f_damping, friction force (3)
        for s in range(n_steps):
            # --- first half kick and drift -------------------------------------------------
            for i in range(n_part):
                for k in range(3):
                    vel[k, c, i] += 0.5 * dt * frc[k, c, i] * inv_m
                    omg[k, c, i] += 0.5 * dt * trq[k, c, i] * inv_i
                    pos[k, c, i] += dt * vel[k, c, i]
                    vp[k, i] = vel[k, c, i] + 0.5 * dt * frc[k, c, i] * inv_m
                    wp[k, i] = omg[k, c, i] + 0.5 * dt * trq[k, c, i] * inv_i
                    frc[k, c, i] = 0.0
                    trq[k, c, i] = 0.0
                frc[2, c, i] = -mass * gravity
            # --- wall motion at the new time ------------------------------------------------
            t = (step0 + s + 1) * dt
            u = 0.0
            uv = 0.0
            if omega > 0.0:
                u = -accel_amp / (omega * omega) * np.sin(omega * t)
                uv = -accel_amp / omega * np.cos(omega * t)
            ux = 0.0
            uy = 0.0
            uz = 0.0
            wvx = 0.0
            wvy = 0.0
            wvz = 0.0
            if drive_axis == 0:
                ux = u
                wvx = uv
            elif drive_axis == 1:
                uy = u
                wvy = uv
            else:
                uz = u
                wvz = uv
            cyc = s // steps_per_cycle
            smp = s // sample_every
            w_wall = 0.0
            d_norm = 0.0
            d_fric = 0.0
            f_drive = 0.0
            n_c = 0
            # --- particle-wall contacts -----------------------------------------------------
            for i in range(n_part):
                px = pos[0, c, i]
                py = pos[1, c, i]
                pz = pos[2, c, i]
                if not (np.isfinite(px) and np.isfinite(py) and np.isfinite(pz)):
                    status[c] = STATUS_NONFINITE
                for w in range(n_walls):
                    nx = wall_n[w, 0]
                    ny = wall_n[w, 1]
                    nz = wall_n[w, 2]
                    dist = nx * (px - ux) + ny * (py - uy) + nz * (pz - uz) + wall_d[w]
                    delta = radius - dist
                    if delta <= 0.0:
                        continue
                    if dist < 0.0:
                        status[c] = STATUS_ESCAPED
                    if delta > max_overlap:
                        status[c] = STATUS_OVERLAP
                    arm = radius - delta
                    ox = wp[0, i]
                    oy = wp[1, i]
                    oz = wp[2, i]
                    # contact point velocity relative to the wall; contact point at -arm*n
                    rvx = vp[0, i] - arm * (oy * nz - oz * ny) - wvx
                    rvy = vp[1, i] - arm * (oz * nx - ox * nz) - wvy
                    rvz = vp[2, i] - arm * (ox * ny - oy * nx) - wvz
                    vn = rvx * nx + rvy * ny + rvz * nz
                    delta_dot = -vn
                    f_el = k_pw * delta * np.sqrt(delta)
                    f_n = f_el + c_pw * np.sqrt(np.sqrt(delta)) * delta_dot
                    if clip_attraction and f_n < 0.0:
                        f_n = 0.0
                    fx = f_n * nx
                    fy = f_n * ny
                    fz = f_n * nz
                    gx = 0.0
                    gy = 0.0
                    gz = 0.0
                    tvx = rvx - vn * nx
                    tvy = rvy - vn * ny
                    tvz = rvz - vn * nz
                    vt = np.sqrt(tvx * tvx + tvy * tvy + tvz * tvz)
                    if vt > 0.0:
                        ft = mu_pw * abs(f_n)
                        if vt < v_reg:
                            ft *= vt / v_reg
                        cap = 0.5 * mt_pw * vt / dt
                        if ft > cap:
                            ft = cap
                        scale = -ft / vt
                        gx = scale * tvx
                        gy = scale * tvy
                        gz = scale * tvz
                        fx += gx
                        fy += gy
                        fz += gz
                        # torque = (-arm n) x g
                        trq[0, c, i] -= arm * (ny * gz - nz * gy)
                        trq[1, c, i] -= arm * (nz * gx - nx * gz)
                        trq[2, c, i] -= arm * (nx * gy - ny * gx)
                    frc[0, c, i] += fx
                    frc[1, c, i] += fy
                    frc[2, c, i] += fz
                    c_idx[0, n_c] = i
                    c_idx[1, n_c] = -1
                    c_val[0, n_c] = nx
                    c_val[1, n_c] = ny
                    c_val[2, n_c] = nz
                    c_val[3, n_c] = arm
                    c_val[4, n_c] = f_n - f_el
                    c_val[5, n_c] = gx
                    c_val[6, n_c] = gy
                    c_val[7, n_c] = gz
                    n_c += 1
                    w_wall += (fx * wvx + fy * wvy + fz * wvz) * dt
                    if drive_axis == 0:
                        f_drive += fx
                    elif drive_axis == 1:
                        f_drive += fy
                    else:
                        f_drive += fz
            # --- particle-particle contacts (brute force, early reject on z) ---------------
            for i in range(n_part - 1):
                xi = pos[0, c, i]
                yi = pos[1, c, i]
                zi = pos[2, c, i]
                for j in range(i + 1, n_part):
                    dz = pos[2, c, j] - zi
                    if dz >= two_r or dz <= -two_r:
                        continue
                    dx = pos[0, c, j] - xi
                    dy = pos[1, c, j] - yi
                    d2 = dx * dx + dy * dy + dz * dz
                    if d2 >= two_r * two_r:
                        continue
                    d = np.sqrt(d2)
                    inv_d = 1.0 / d
                    nx = dx * inv_d
                    ny = dy * inv_d
                    nz = dz * inv_d
                    delta = two_r - d
                    if delta > max_overlap:
                        status[c] = STATUS_OVERLAP
                    arm = radius - 0.5 * delta
                    # omega_i x (arm n) - omega_j x (-arm n) = arm (omega_i + omega_j) x n
                    sx = wp[0, i] + wp[0, j]
                    sy = wp[1, i] + wp[1, j]
                    sz = wp[2, i] + wp[2, j]
                    rvx = vp[0, i] - vp[0, j] + arm * (sy * nz - sz * ny)
                    rvy = vp[1, i] - vp[1, j] + arm * (sz * nx - sx * nz)
                    rvz = vp[2, i] - vp[2, j] + arm * (sx * ny - sy * nx)
                    delta_dot = rvx * nx + rvy * ny + rvz * nz
                    f_el = k_pp * delta * np.sqrt(delta)
                    f_n = f_el + c_pp * np.sqrt(np.sqrt(delta)) * delta_dot
                    if clip_attraction and f_n < 0.0:
                        f_n = 0.0
                    # force on i: -f_n n (+ friction g); on j: the opposite
                    fx = -f_n * nx
                    fy = -f_n * ny
                    fz = -f_n * nz
                    gx = 0.0
                    gy = 0.0
                    gz = 0.0
                    tvx = rvx - delta_dot * nx
                    tvy = rvy - delta_dot * ny
                    tvz = rvz - delta_dot * nz
                    vt = np.sqrt(tvx * tvx + tvy * tvy + tvz * tvz)
                    if vt > 0.0:
                        ft = mu_pp * abs(f_n)
                        if vt < v_reg:
                            ft *= vt / v_reg
                        cap = 0.5 * mt_pp * vt / dt
                        if ft > cap:
                            ft = cap
                        scale = -ft / vt
                        gx = scale * tvx
                        gy = scale * tvy
                        gz = scale * tvz
                        fx += gx
                        fy += gy
                        fz += gz
                        # torque on i and on j: arm n x g (same for both)
                        tx = arm * (ny * gz - nz * gy)
                        ty = arm * (nz * gx - nx * gz)
                        tz = arm * (nx * gy - ny * gx)
                        trq[0, c, i] += tx
                        trq[1, c, i] += ty
                        trq[2, c, i] += tz
                        trq[0, c, j] += tx
                        trq[1, c, j] += ty
                        trq[2, c, j] += tz
                    frc[0, c, i] += fx
                    frc[1, c, i] += fy
                    frc[2, c, i] += fz
                    frc[0, c, j] -= fx
                    frc[1, c, j] -= fy
                    frc[2, c, j] -= fz
                    c_idx[0, n_c] = i
                    c_idx[1, n_c] = j
                    c_val[0, n_c] = nx
                    c_val[1, n_c] = ny
                    c_val[2, n_c] = nz
                    c_val[3, n_c] = arm
                    c_val[4, n_c] = f_n - f_el
                    c_val[5, n_c] = gx
                    c_val[6, n_c] = gy
                    c_val[7, n_c] = gz
                    n_c += 1
            # --- second half kick ----------------------------------------------------------
            for i in range(n_part):
                for k in range(3):
                    vel[k, c, i] += 0.5 * dt * frc[k, c, i] * inv_m
                    omg[k, c, i] += 0.5 * dt * trq[k, c, i] * inv_i
            # --- dissipation with the new full-step velocities ---------------------------
            # v(t) is what the kicks of this step's force act on (sum_t F(t).v(t) dt is the
            # kinetic energy change to second order), so the tally closes the energy balance.
            for q in range(n_c):
                i = c_idx[0, q]
                j = c_idx[1, q]
                nx = c_val[0, q]
                ny = c_val[1, q]
                nz = c_val[2, q]
                arm = c_val[3, q]
                ox = omg[0, c, i]
                oy = omg[1, c, i]
                oz = omg[2, c, i]
                if j < 0:
                    rvx = vel[0, c, i] - arm * (oy * nz - oz * ny) - wvx
                    rvy = vel[1, c, i] - arm * (oz * nx - ox * nz) - wvy
                    rvz = vel[2, c, i] - arm * (ox * ny - oy * nx) - wvz
                    delta_dot = -(rvx * nx + rvy * ny + rvz * nz)
                else:
                    ox += omg[0, c, j]
                    oy += omg[1, c, j]
                    oz += omg[2, c, j]
                    rvx = vel[0, c, i] - vel[0, c, j] + arm * (oy * nz - oz * ny)
                    rvy = vel[1, c, i] - vel[1, c, j] + arm * (oz * nx - ox * nz)
                    rvz = vel[2, c, i] - vel[2, c, j] + arm * (ox * ny - oy * nx)
                    delta_dot = rvx * nx + rvy * ny + rvz * nz
                d_norm += c_val[4, q] * delta_dot * dt
                d_fric -= (c_val[5, q] * rvx + c_val[6, q] * rvy + c_val[7, q] * rvz) * dt
            tally[c, cyc, 0] += w_wall
            tally[c, cyc, 1] += d_norm
            tally[c, cyc, 2] += d_fric
            samples[c, smp] += f_drive
            if status[c] != STATUS_OK:
                fail_step[c] = step0 + s + 1
                break
    return 0
