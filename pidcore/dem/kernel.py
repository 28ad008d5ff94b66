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
  2 dissipated by friction (tangential model, see below)
with the full-step velocities v(t) after the second kick (see above). Normal damping only
needs the translational velocities: rotation moves a contact point within the tangent plane.
Samples: sum over the sample interval of the drive-axis component of the force the walls
exert on the particles (divide by ``sample_every`` for the interval mean).

Tangential force, ``stick_slip`` true (default; :mod:`pidcore.dem.contact`): a spring per
contact, stretched by the contact points' tangential displacement over each step (drift
velocities, i.e. the displacement the positions really made, and the walls' displacement),
projected into the current tangent plane, capped at mu |f_n|. The friction tally is the work
of the contact on the spring minus the spring energy gained (trapezoidal force times
displacement, which is what velocity Verlet changes the kinetic energy by): exactly zero
while stuck. A spring left stretched when its contact opens is counted as dissipated, and its
energy, 1/2 k_t |xi|^2, is part of the stored (elastic) energy until then. Pair springs live
in an N x N table [i, j], wall springs in N x walls, so they survive neighbour-list rebuilds.

``stick_slip`` false, Eq. 5 as written: f_t = -mu |f_n| v_t/|v_t|, scaled linearly below
``v_reg`` and capped at m_t |v_t| / (2 dt) (m_t: effective tangential mass of the contact):
the cap removes at most half the slip per step, so at the slide-to-stick transition the slip
decays geometrically instead of chattering around zero, and friction never reverses the slip
nor injects energy. Tally: sum -f_t . v_t(t) dt.

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


#: Verlet skin of the neighbour lists, as a fraction of the radius. Purely numerical: a pair
#: (or a particle and a wall) is a candidate while closer than contact + skin, and the lists
#: are rebuilt before any particle has moved skin/2, so no contact is ever missed and the set
#: and order of contacts (hence every result bit) are those of the brute-force search.
NEIGHBOUR_SKIN_FRACTION = 0.3


@njit(cache=True, inline="always")
def _normal_force(delta, delta_dot, k_n, c_n, clip_attraction):
    """Eq. 2: Hertz elastic part k delta^1.5 and total with Tsuji damping c delta^0.25 ddelta/dt.

    ``c_n`` is alpha sqrt(m* k_n) (Eq. 3-4); with ``clip_attraction`` the total may not pull.
    Returns (elastic, total) normal force magnitudes, N.
    """
    sq = np.sqrt(delta)
    f_el = k_n * delta * sq
    f_n = f_el + c_n * np.sqrt(sq) * delta_dot
    if clip_attraction and f_n < 0.0:
        f_n = 0.0
    return f_el, f_n


@njit(cache=True, inline="always")
def _friction_scale(f_n, vt, mu, v_reg, m_t, dt):
    """Eq. 5 as a factor on the tangential slip velocity: f_t = scale * v_t.

    Coulomb mu |f_n| against the slip, scaled down linearly below ``v_reg`` (no chatter at
    v_t -> 0) and capped at m_t v_t / (2 dt) so that one step can never reverse the slip (friction
    never injects energy). ``vt`` > 0.
    """
    ft = mu * abs(f_n)
    if vt < v_reg:
        ft *= vt / v_reg
    cap = 0.5 * m_t * vt / dt
    if ft > cap:
        ft = cap
    return -ft / vt


@njit(cache=True, inline="always")
def _friction_force(rvx, rvy, rvz, vn, nx, ny, nz, f_n, mu, v_reg, m_t, dt):
    """Eq. 5 friction vector on the contact from the relative contact-point velocity rv.

    The slip is rv minus its normal part ``vn`` along n; no slip, no force. Returns (gx, gy, gz), N.
    """
    tvx = rvx - vn * nx
    tvy = rvy - vn * ny
    tvz = rvz - vn * nz
    vt = np.sqrt(tvx * tvx + tvy * tvy + tvz * tvz)
    if vt > 0.0:
        scale = _friction_scale(f_n, vt, mu, v_reg, m_t, dt)
        return scale * tvx, scale * tvy, scale * tvz
    return 0.0, 0.0, 0.0


@njit(cache=True, inline="always")
def _spring_force(qx, qy, qz, live, a, b, dsx, dsy, dsz, nx, ny, nz, f_n, mu, k_t):
    """Stick-slip tangential spring (Eq. 5 with a tangential spring, capped by mu |f_n|).

    The spring of contact [a, b] lives in the tables ``qx``, ``qy``, ``qz`` (its stretch xi,
    updated in place) and ``live`` (set). The stretch is projected into the current tangent
    plane, the step's tangential displacement ds of the contact points is added, and the
    force -k_t xi is capped at mu |f_n| by shortening xi (sliding).

    Returns (gx, gy, gz, dissipated): the force on the contact's first body, N, and the
    energy lost, J. Dissipated = work of the contact on the spring minus the spring energy
    gained, with the work taken as the mean of the old and new spring forces times ds
    (velocity Verlet changes the kinetic energy by exactly that mean force times the drift,
    so the balance closes): zero while stuck, mu |f_n| |ds| while sliding steadily.
    """
    sx = qx[a, b]
    sy = qy[a, b]
    sz = qz[a, b]
    # into the tangent plane: the normal part of xi (second order in the normal's turn per
    # step) is dropped and its energy counted as lost, so the balance still closes
    sn = sx * nx + sy * ny + sz * nz
    sx -= sn * nx
    sy -= sn * ny
    sz -= sn * nz
    turned = 0.5 * k_t * sn * sn
    old2 = sx * sx + sy * sy + sz * sz
    dn = dsx * nx + dsy * ny + dsz * nz
    dsx -= dn * nx
    dsy -= dn * ny
    dsz -= dn * nz
    ax = sx + dsx
    ay = sy + dsy
    az = sz + dsz
    trial2 = ax * ax + ay * ay + az * az
    limit = mu * abs(f_n)
    lost = turned
    if k_t * k_t * trial2 > limit * limit:
        keep = limit / (k_t * np.sqrt(trial2))
        ax *= keep
        ay *= keep
        az *= keep
        work = 0.5 * k_t * ((sx + ax) * dsx + (sy + ay) * dsy + (sz + az) * dsz)
        gained = 0.5 * k_t * (ax * ax + ay * ay + az * az - old2)
        lost = turned + work - gained
    qx[a, b] = ax
    qy[a, b] = ay
    qz[a, b] = az
    live[a, b] = True
    return -k_t * ax, -k_t * ay, -k_t * az, lost


@njit(cache=True, inline="always")
def _release_spring(qx, qy, qz, live, a, b, k_t):
    """Contact [a, b] is open: clear its spring; returns the energy it still held, J.

    That energy leaves with the contact, so it is counted as dissipated by friction.
    """
    if not live[a, b]:
        return 0.0
    held = 0.5 * k_t * (qx[a, b] ** 2 + qy[a, b] ** 2 + qz[a, b] ** 2)
    qx[a, b] = 0.0
    qy[a, b] = 0.0
    qz[a, b] = 0.0
    live[a, b] = False
    return held


@njit(cache=True, parallel=True)
def advance_cells(pos, vel, omg, frc, trq, wall_n, wall_d,
                  radius, mass, inertia,
                  k_pp, c_pp, mu_pp, mt_pp, k_pw, c_pw, mu_pw, mt_pw,
                  v_reg, clip_attraction, gravity,
                  stick_slip, kt_pp, kt_pw, spr_pp, spr_pw,
                  dt, step0, n_steps, omega, accel_amp, drive_axis,
                  steps_per_cycle, sample_every, max_overlap_fraction,
                  tally, samples, status, fail_step):
    n_cells = pos.shape[1]
    for c in prange(n_cells):
        if status[c] != STATUS_OK:
            continue
        _advance_cell(c, pos, vel, omg, frc, trq, wall_n, wall_d,
                      radius, mass, inertia,
                      k_pp, c_pp, mu_pp, mt_pp, k_pw, c_pw, mu_pw, mt_pw,
                      v_reg, clip_attraction, gravity,
                      stick_slip, kt_pp, kt_pw, spr_pp, spr_pw,
                      dt, step0, n_steps, omega, accel_amp, drive_axis,
                      steps_per_cycle, sample_every, max_overlap_fraction,
                      tally, samples, status, fail_step)
    return 0


@njit(cache=True, error_model="numpy")
def _advance_cell(c, pos, vel, omg, frc, trq, wall_n, wall_d,
                  radius, mass, inertia,
                  k_pp, c_pp, mu_pp, mt_pp, k_pw, c_pw, mu_pw, mt_pw,
                  v_reg, clip_attraction, gravity,
                  stick_slip, kt_pp, kt_pw, spr_pp, spr_pw,
                  dt, step0, n_steps, omega, accel_amp, drive_axis,
                  steps_per_cycle, sample_every, max_overlap_fraction,
                  tally, samples, status, fail_step):
    """Advance cell ``c`` by ``n_steps`` (see the module docstring).

    Speed (results are bit-identical to a brute-force search over all pairs and walls):
    the cell's state is copied into contiguous 1-D arrays for the chunk; particle pairs
    and particle-wall pairs come from Verlet lists (candidates within contact + skin, kept
    in the brute-force order i < j, walls ascending, so forces are summed in the same order)
    rebuilt whenever a particle has moved skin/2 since the last build (relative to the
    cell for the walls, which move with it).
    """
    n_part = pos.shape[2]
    n_walls = wall_n.shape[0]
    inv_m = 1.0 / mass
    inv_i = 1.0 / inertia
    two_r = 2.0 * radius
    max_overlap = max_overlap_fraction * radius
    skin = NEIGHBOUR_SKIN_FRACTION * radius
    half_skin2 = 0.25 * skin * skin
    pair_reach2 = (two_r + skin) * (two_r + skin)
    wall_reach = radius + skin
    # contiguous per-cell copies (written back at the end of the chunk)
    px = pos[0, c].copy()
    py = pos[1, c].copy()
    pz = pos[2, c].copy()
    vx = vel[0, c].copy()
    vy = vel[1, c].copy()
    vz = vel[2, c].copy()
    ox = omg[0, c].copy()
    oy = omg[1, c].copy()
    oz = omg[2, c].copy()
    fx = frc[0, c].copy()
    fy = frc[1, c].copy()
    fz = frc[2, c].copy()
    tx = trq[0, c].copy()
    ty = trq[1, c].copy()
    tz = trq[2, c].copy()
    # predicted full-step velocities (see module docstring)
    vpx = np.empty(n_part)
    vpy = np.empty(n_part)
    vpz = np.empty(n_part)
    wpx = np.empty(n_part)
    wpy = np.empty(n_part)
    wpz = np.empty(n_part)
    wnx = wall_n[:, 0].copy()
    wny = wall_n[:, 1].copy()
    wnz = wall_n[:, 2].copy()
    wd = wall_d.copy()
    # tangential springs (stick-slip model): [i, j] for pairs i < j, [i, wall] for walls
    qpx = spr_pp[0, c].copy()
    qpy = spr_pp[1, c].copy()
    qpz = spr_pp[2, c].copy()
    qwx = spr_pw[0, c].copy()
    qwy = spr_pw[1, c].copy()
    qwz = spr_pw[2, c].copy()
    # which springs may hold a stretch (one byte read per idle candidate instead of three
    # floats): set on contact, cleared when the contact opens
    live_p = (qpx != 0.0) | (qpy != 0.0) | (qpz != 0.0)
    live_w = (qwx != 0.0) | (qwy != 0.0) | (qwz != 0.0)
    u_prev = 0.0  # cell displacement along the drive axis at the previous step
    if omega > 0.0:
        t_prev = step0 * dt  # same rounding as t below, so chunking does not change bits
        u_prev = -accel_amp / (omega * omega) * np.sin(omega * t_prev)
    max_pairs = n_part * (n_part - 1) // 2
    max_contacts = n_walls * n_part + max_pairs
    c_idx = np.empty((2, max_contacts), dtype=np.int64)  # i, j (j < 0: wall)
    c_val = np.empty((8, max_contacts))  # n (3), arm, f_damping, friction force (3)
    # Verlet lists: pair candidates (i < j, brute-force order), wall candidates per particle
    nb_i = np.empty(max_pairs, dtype=np.int64)
    nb_j = np.empty(max_pairs, dtype=np.int64)
    n_nb = 0
    wl_start = np.empty(n_part + 1, dtype=np.int64)
    wl_w = np.empty(n_walls * n_part, dtype=np.int64)
    ref_x = np.empty(n_part)  # positions at the last build (absolute)
    ref_y = np.empty(n_part)
    ref_z = np.empty(n_part)
    ref_ux = 0.0  # cell displacement at the last build
    ref_uy = 0.0
    ref_uz = 0.0
    rebuild = True
    for s in range(n_steps):
        # --- first half kick and drift -------------------------------------------------
        for i in range(n_part):
            vx[i] += 0.5 * dt * fx[i] * inv_m
            vy[i] += 0.5 * dt * fy[i] * inv_m
            vz[i] += 0.5 * dt * fz[i] * inv_m
            ox[i] += 0.5 * dt * tx[i] * inv_i
            oy[i] += 0.5 * dt * ty[i] * inv_i
            oz[i] += 0.5 * dt * tz[i] * inv_i
            px[i] += dt * vx[i]
            py[i] += dt * vy[i]
            pz[i] += dt * vz[i]
            vpx[i] = vx[i] + 0.5 * dt * fx[i] * inv_m
            vpy[i] = vy[i] + 0.5 * dt * fy[i] * inv_m
            vpz[i] = vz[i] + 0.5 * dt * fz[i] * inv_m
            wpx[i] = ox[i] + 0.5 * dt * tx[i] * inv_i
            wpy[i] = oy[i] + 0.5 * dt * ty[i] * inv_i
            wpz[i] = oz[i] + 0.5 * dt * tz[i] * inv_i
            fx[i] = 0.0
            fy[i] = 0.0
            fz[i] = -mass * gravity
            tx[i] = 0.0
            ty[i] = 0.0
            tz[i] = 0.0
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
        # wall displacement over this step (the tangential springs follow real displacements)
        dwx = 0.0
        dwy = 0.0
        dwz = 0.0
        if drive_axis == 0:
            ux = u
            wvx = uv
            dwx = u - u_prev
        elif drive_axis == 1:
            uy = u
            wvy = uv
            dwy = u - u_prev
        else:
            uz = u
            wvz = uv
            dwz = u - u_prev
        u_prev = u
        # --- Verlet lists: rebuild once a particle may have moved skin/2 ----------------
        if not rebuild:
            dux = ux - ref_ux
            duy = uy - ref_uy
            duz = uz - ref_uz
            for i in range(n_part):
                ax = px[i] - ref_x[i]
                ay = py[i] - ref_y[i]
                az = pz[i] - ref_z[i]
                if ax * ax + ay * ay + az * az >= half_skin2:
                    rebuild = True
                    break
                ax -= dux
                ay -= duy
                az -= duz
                if ax * ax + ay * ay + az * az >= half_skin2:
                    rebuild = True
                    break
        if rebuild:
            rebuild = False
            ref_ux = ux
            ref_uy = uy
            ref_uz = uz
            n_nb = 0
            n_wl = 0
            for i in range(n_part):
                ref_x[i] = px[i]
                ref_y[i] = py[i]
                ref_z[i] = pz[i]
                wl_start[i] = n_wl
                for w in range(n_walls):
                    dist = (wnx[w] * (px[i] - ux) + wny[w] * (py[i] - uy)
                            + wnz[w] * (pz[i] - uz) + wd[w])
                    # not finite: keep the wall so the contact loop flags the cell
                    if not dist >= wall_reach:
                        wl_w[n_wl] = w
                        n_wl += 1
                for j in range(i + 1, n_part):
                    dx = px[j] - px[i]
                    dy = py[j] - py[i]
                    dz = pz[j] - pz[i]
                    if not dx * dx + dy * dy + dz * dz >= pair_reach2:
                        nb_i[n_nb] = i
                        nb_j[n_nb] = j
                        n_nb += 1
            wl_start[n_part] = n_wl
        cyc = s // steps_per_cycle
        smp = s // sample_every
        w_wall = 0.0
        d_norm = 0.0
        d_fric = 0.0
        f_drive = 0.0
        n_c = 0
        # --- particle-wall contacts -----------------------------------------------------
        for i in range(n_part):
            pxi = px[i]
            pyi = py[i]
            pzi = pz[i]
            if not (np.isfinite(pxi) and np.isfinite(pyi) and np.isfinite(pzi)):
                status[c] = STATUS_NONFINITE
            for q in range(wl_start[i], wl_start[i + 1]):
                w = wl_w[q]
                nx = wnx[w]
                ny = wny[w]
                nz = wnz[w]
                dist = nx * (pxi - ux) + ny * (pyi - uy) + nz * (pzi - uz) + wd[w]
                delta = radius - dist
                if delta <= 0.0:
                    d_fric += _release_spring(qwx, qwy, qwz, live_w, i, w, kt_pw)
                    continue
                if dist < 0.0:
                    status[c] = STATUS_ESCAPED
                if delta > max_overlap:
                    status[c] = STATUS_OVERLAP
                arm = radius - delta
                # contact point velocity relative to the wall (contact point at -arm*n); the
                # rotation part lies in the tangent plane and is added only where needed
                rvx = vpx[i] - wvx
                rvy = vpy[i] - wvy
                rvz = vpz[i] - wvz
                vn = rvx * nx + rvy * ny + rvz * nz
                delta_dot = -vn
                f_el, f_n = _normal_force(delta, delta_dot, k_pw, c_pw, clip_attraction)
                if stick_slip:
                    # contact-point displacement relative to the wall over the step, with the
                    # drift (half-step) velocities the positions moved with
                    oxi = ox[i]
                    oyi = oy[i]
                    ozi = oz[i]
                    gx, gy, gz, lost = _spring_force(
                        qwx, qwy, qwz, live_w, i, w,
                        dt * (vx[i] - arm * (oyi * nz - ozi * ny)) - dwx,
                        dt * (vy[i] - arm * (ozi * nx - oxi * nz)) - dwy,
                        dt * (vz[i] - arm * (oxi * ny - oyi * nx)) - dwz,
                        nx, ny, nz, f_n, mu_pw, kt_pw)
                    d_fric += lost
                else:
                    wxi = wpx[i]
                    wyi = wpy[i]
                    wzi = wpz[i]
                    rvx -= arm * (wyi * nz - wzi * ny)
                    rvy -= arm * (wzi * nx - wxi * nz)
                    rvz -= arm * (wxi * ny - wyi * nx)
                    gx, gy, gz = _friction_force(rvx, rvy, rvz, vn, nx, ny, nz, f_n, mu_pw,
                                                 v_reg, mt_pw, dt)
                cfx = f_n * nx + gx
                cfy = f_n * ny + gy
                cfz = f_n * nz + gz
                # torque = (-arm n) x g
                tx[i] -= arm * (ny * gz - nz * gy)
                ty[i] -= arm * (nz * gx - nx * gz)
                tz[i] -= arm * (nx * gy - ny * gx)
                fx[i] += cfx
                fy[i] += cfy
                fz[i] += cfz
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
                w_wall += (cfx * wvx + cfy * wvy + cfz * wvz) * dt
                if drive_axis == 0:
                    f_drive += cfx
                elif drive_axis == 1:
                    f_drive += cfy
                else:
                    f_drive += cfz
        # --- particle-particle contacts (Verlet candidates) -----------------------------
        for q in range(n_nb):
            i = nb_i[q]
            j = nb_j[q]
            dz = pz[j] - pz[i]
            touching = dz < two_r and dz > -two_r
            if touching:
                dx = px[j] - px[i]
                dy = py[j] - py[i]
                d2 = dx * dx + dy * dy + dz * dz
                touching = d2 < two_r * two_r
            if not touching:
                d_fric += _release_spring(qpx, qpy, qpz, live_p, i, j, kt_pp)
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
            rvx = vpx[i] - vpx[j]
            rvy = vpy[i] - vpy[j]
            rvz = vpz[i] - vpz[j]
            delta_dot = rvx * nx + rvy * ny + rvz * nz
            f_el, f_n = _normal_force(delta, delta_dot, k_pp, c_pp, clip_attraction)
            # force on i: -f_n n (+ friction g); on j: the opposite
            if stick_slip:
                hx = ox[i] + ox[j]
                hy = oy[i] + oy[j]
                hz = oz[i] + oz[j]
                gx, gy, gz, lost = _spring_force(
                    qpx, qpy, qpz, live_p, i, j,
                    dt * (vx[i] - vx[j] + arm * (hy * nz - hz * ny)),
                    dt * (vy[i] - vy[j] + arm * (hz * nx - hx * nz)),
                    dt * (vz[i] - vz[j] + arm * (hx * ny - hy * nx)),
                    nx, ny, nz, f_n, mu_pp, kt_pp)
                d_fric += lost
            else:
                # omega_i x (arm n) - omega_j x (-arm n) = arm (omega_i + omega_j) x n
                sx = wpx[i] + wpx[j]
                sy = wpy[i] + wpy[j]
                sz = wpz[i] + wpz[j]
                rvx += arm * (sy * nz - sz * ny)
                rvy += arm * (sz * nx - sx * nz)
                rvz += arm * (sx * ny - sy * nx)
                gx, gy, gz = _friction_force(rvx, rvy, rvz, delta_dot, nx, ny, nz, f_n, mu_pp,
                                             v_reg, mt_pp, dt)
            cfx = -f_n * nx + gx
            cfy = -f_n * ny + gy
            cfz = -f_n * nz + gz
            # torque on i and on j: arm n x g (same for both)
            ctx = arm * (ny * gz - nz * gy)
            cty = arm * (nz * gx - nx * gz)
            ctz = arm * (nx * gy - ny * gx)
            tx[i] += ctx
            ty[i] += cty
            tz[i] += ctz
            tx[j] += ctx
            ty[j] += cty
            tz[j] += ctz
            fx[i] += cfx
            fy[i] += cfy
            fz[i] += cfz
            fx[j] -= cfx
            fy[j] -= cfy
            fz[j] -= cfz
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
            vx[i] += 0.5 * dt * fx[i] * inv_m
            vy[i] += 0.5 * dt * fy[i] * inv_m
            vz[i] += 0.5 * dt * fz[i] * inv_m
            ox[i] += 0.5 * dt * tx[i] * inv_i
            oy[i] += 0.5 * dt * ty[i] * inv_i
            oz[i] += 0.5 * dt * tz[i] * inv_i
        # --- dissipation with the new full-step velocities ---------------------------
        # v(t) is what the kicks of this step's force act on (sum_t F(t).v(t) dt is the
        # kinetic energy change to second order), so the tally closes the energy balance.
        for q in range(n_c):
            i = c_idx[0, q]
            j = c_idx[1, q]
            nx = c_val[0, q]
            ny = c_val[1, q]
            nz = c_val[2, q]
            # translation only: rotation moves the contact point along the tangent plane
            if j < 0:
                rvx = vx[i] - wvx
                rvy = vy[i] - wvy
                rvz = vz[i] - wvz
                delta_dot = -(rvx * nx + rvy * ny + rvz * nz)
            else:
                rvx = vx[i] - vx[j]
                rvy = vy[i] - vy[j]
                rvz = vz[i] - vz[j]
                delta_dot = rvx * nx + rvy * ny + rvz * nz
            d_norm += c_val[4, q] * delta_dot * dt
            if stick_slip:
                continue  # friction loss was tallied where the spring slid
            arm = c_val[3, q]
            sx = ox[i]
            sy = oy[i]
            sz = oz[i]
            if j < 0:
                rvx -= arm * (sy * nz - sz * ny)
                rvy -= arm * (sz * nx - sx * nz)
                rvz -= arm * (sx * ny - sy * nx)
            else:
                sx += ox[j]
                sy += oy[j]
                sz += oz[j]
                rvx += arm * (sy * nz - sz * ny)
                rvy += arm * (sz * nx - sx * nz)
                rvz += arm * (sx * ny - sy * nx)
            d_fric -= (c_val[5, q] * rvx + c_val[6, q] * rvy + c_val[7, q] * rvz) * dt
        tally[c, cyc, 0] += w_wall
        tally[c, cyc, 1] += d_norm
        tally[c, cyc, 2] += d_fric
        samples[c, smp] += f_drive
        if status[c] != STATUS_OK:
            fail_step[c] = step0 + s + 1
            break
    pos[0, c] = px
    pos[1, c] = py
    pos[2, c] = pz
    vel[0, c] = vx
    vel[1, c] = vy
    vel[2, c] = vz
    omg[0, c] = ox
    omg[1, c] = oy
    omg[2, c] = oz
    frc[0, c] = fx
    frc[1, c] = fy
    frc[2, c] = fz
    trq[0, c] = tx
    trq[1, c] = ty
    trq[2, c] = tz
    spr_pp[0, c] = qpx
    spr_pp[1, c] = qpy
    spr_pp[2, c] = qpz
    spr_pw[0, c] = qwx
    spr_pw[1, c] = qwy
    spr_pw[2, c] = qwz
