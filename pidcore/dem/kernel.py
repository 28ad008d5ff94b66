"""Numba time-stepping kernel: all cells, a chunk of steps, no Python objects inside.

State is structure-of-arrays: ``pos[0]`` is x of every particle of every cell (shape (K, N)),
``pos[1]`` y, ``pos[2]`` z; likewise ``vel``, ``omg`` (angular velocity), ``frc`` and ``trq``
(force and torque of the last evaluation, kept between chunks). Cells are independent: the
kernel advances the cells ``first_cell`` to ``end_cell - 1`` and releases the GIL, so
:func:`pidcore.dem.state.advance` runs slices of the cells on threads. Each cell's arithmetic
is serial and free of random numbers, so the result does not depend on the thread count.
(Python threads rather than Numba's ``parallel=True``: the parallel-loop machinery took 60 %
of a cold compile, ~28 s of ~46 s per law set, for the same speed.)

Integrator: velocity Verlet (kick-drift-kick). Velocity-dependent forces (damping, friction)
use the predicted full-step velocity v_pred = v(t-dt) + dt F(t-dt)/m (second order; LIGGGHTS
uses the half-step velocity, first order). The dissipation is tallied after the second kick
with the full-step velocity v(t) that this step's force acts on: then sum F(t).v(t) dt is the
kinetic energy change to second order and the energy balance closes to ~0.2-0.6 % at 10-12
steps per contact (with the half-step velocity it missed ~3 %). The walls move rigidly with
the cell: u(t) = -(a/w^2) sin(w t) along the drive axis, wall velocity -(a/w) cos(w t).

Contacts. Every contact, particle-particle or particle-wall, goes through one body
(:func:`_contact`) that calls the laws of :mod:`pidcore.dem.contact` once each: Hertz + Tsuji
normal force, the tangential law, rolling resistance. The body sees the contact from its first
particle i: unit normal n from i towards the partner (for a wall, minus the wall's inward
normal), overlap delta, contact point at arm n from i's centre; force on i -f_n n + f_t, on
the partner the opposite; torque arm n x f_t on both particles of a pair; rolling torque M_r
on i and -M_r on the partner. The parameters come per pair of materials as a vector (slots
``LAW_*`` of :mod:`pidcore.dem.contact`), one for particle pairs and one for the walls.

Energy tallies per cell and cycle (index ``[cell, cycle, k]``):
  0 work of the walls on the particles, sum f_wall_on_particle . v_wall dt
  1 dissipated by normal damping, sum f_damping * delta_dot(t) * dt
  2 dissipated by friction (tangential law, see below)
  3 dissipated by rolling resistance (its spring's plastic slip and its dashpot)
with the full-step velocities v(t) after the second kick (see above). Normal damping only
needs the translational velocities: rotation moves a contact point within the tangent plane.
Samples: sum over the sample interval of the drive-axis component of the force the walls
exert on the particles (divide by ``sample_every`` for the interval mean).

Contact history (``hist``, per contact [i, j] for pairs i < j and [i, wall] for walls; slots
``HIST_*``): the tangential spring's stretch xi (3), whether it slides (static friction), the
stiffness k_t it is stored with, and the rolling spring's angle theta (3). A contact that
opens takes its springs' energy with it (counted as dissipated, friction or rolling).

Tangential force, ``stick_slip`` true (default; :func:`pidcore.dem.contact.capped_spring`): a
spring per contact, stretched by the contact points' tangential displacement over each step
(drift velocities, i.e. the displacement the positions really made, and the walls'
displacement), projected into the current tangent plane. It sticks while k_t |xi| <= mu_s
|f_n|; once over, it slides at mu |f_n| (xi cut to that length) until a step's trial force
stays within mu |f_n| again (the slip stopped): static and sliding friction. The friction
tally is the work of the contact on the spring minus the spring energy gained (trapezoidal
force times displacement, which is what velocity Verlet changes the kinetic energy by):
exactly zero while stuck. k_t is constant, or with the Mindlin option 8 G* sqrt(R* delta) of
the current overlap (the stretch is rescaled as the overlap changes; the stored energy 1/2
k_t |xi|^2 with the contact's current k_t can only fall by it, and the fall is tallied).

``stick_slip`` false, Eq. 5 as written: f_t = -mu |f_n| v_t/|v_t|, scaled linearly below
``v_reg`` and capped at m_t |v_t| / (2 dt) (m_t: effective tangential mass of the contact):
the cap removes at most half the slip per step, so at the slide-to-stick transition the slip
decays geometrically instead of chattering around zero, and friction never reverses the slip
nor injects energy. Tally: sum -f_t . v_t(t) dt. Static friction does not apply.

Rolling resistance (Ai et al., Powder Technol. 206 (2011) 269, model C; LIGGGHTS ``epsd2``
plus the optional dashpot of ``epsd``; LAMMPS ``rolling sds``): a rotational spring on the
relative rolling angle theta (the tangent-plane part of the relative rotation (omega_i -
omega_j) dt), M_r = -k_r theta, capped at mu_r R* |f_n| (the same elastic-plastic spring law
as the tangential one), plus a dashpot -C_r omega_rel while below the cap.

Status per cell: 0 ok; 1 overlap above ``max_overlap_fraction * r``; 2 a particle centre left
the cell; 3 non-finite state. ``fail_step`` holds the step where it happened.
"""

from __future__ import annotations

import numpy as np
from numba import literally, njit, types
from numba.extending import overload

from .contact import (
    LAW_DAMPING,
    LAW_MINDLIN_FACTOR,
    LAW_ROLLING_ARM,
    LAW_ROLLING_DAMPING,
    LAW_ROLLING_STIFFNESS,
    LAW_SLIDING,
    LAW_STATIC,
    LAW_STIFFNESS,
    LAW_TANGENTIAL_MASS,
    LAW_TANGENTIAL_STIFFNESS,
    capped_spring,
    coulomb_friction_scale,
    hertz_elastic_energy,
    hertz_normal_force,
    mindlin_tangential_stiffness,
)

STATUS_OK = 0
STATUS_OVERLAP = 1
STATUS_ESCAPED = 2
STATUS_NONFINITE = 3
#: Tally columns: walls' work, normal damping, friction, rolling resistance.
N_TALLIES = 4
TALLY_WORK = 0
TALLY_NORMAL = 1
TALLY_FRICTION = 2
TALLY_ROLLING = 3

#: Slots of the contact history (last axis of ``CellsState.spring_pp`` / ``spring_pw``).
HIST_XI = 0  # tangential spring stretch xi, 3 slots, m
HIST_SLIDING = 3  # 1.0 while the tangential spring slides (static friction broken)
HIST_KT = 4  # k_t the stretch is stored with, N/m (0: no contact)
HIST_ROLL = 5  # rolling spring angle theta, 3 slots, rad
N_HISTORY = 8

#: Verlet skin of the neighbour lists, as a fraction of the radius. Purely numerical: a pair
#: (or a particle and a wall) is a candidate while closer than contact + skin, and the lists
#: are rebuilt before any particle has moved skin/2, so no contact is ever missed and the set
#: and order of contacts (hence every result bit) are those of the brute-force search.
NEIGHBOUR_SKIN_FRACTION = 0.3


@njit(cache=True, inline="always")
def _release(hist, a, b, k_r):
    """Contact [a, b] is open: clear its history; returns (tangential, rolling) energy, J.

    The energy its springs still held leaves with the contact: counted as dissipated.
    """
    k_t = hist[a, b, HIST_KT]
    if k_t == 0.0:
        return 0.0, 0.0
    held_t = 0.5 * k_t * (hist[a, b, 0] ** 2 + hist[a, b, 1] ** 2 + hist[a, b, 2] ** 2)
    held_r = 0.0
    if k_r > 0.0:
        held_r = 0.5 * k_r * (hist[a, b, HIST_ROLL] ** 2 + hist[a, b, HIST_ROLL + 1] ** 2
                              + hist[a, b, HIST_ROLL + 2] ** 2)
    for q in range(hist.shape[2]):
        hist[a, b, q] = 0.0
    return held_t, held_r


@njit(cache=True, inline="never")
def _coulomb_force(law, nx, ny, nz, arm, rvx, rvy, rvz, hpx, hpy, hpz, delta_dot, f_n,
                   v_reg, dt):
    """Eq. 5 friction on i (``tangential_model="coulomb"``): (gx, gy, gz), N.

    Out of line (not inlined into the contact body) so that the default stick-slip path's
    machine code stays small: an unused branch inlined into the hot loop cost it ~25 %.
    """
    # slip velocity of the contact points: rv + arm hp x n, minus its normal part
    tvx = rvx + arm * (hpy * nz - hpz * ny)
    tvy = rvy + arm * (hpz * nx - hpx * nz)
    tvz = rvz + arm * (hpx * ny - hpy * nx)
    tvx -= delta_dot * nx
    tvy -= delta_dot * ny
    tvz -= delta_dot * nz
    vt = np.sqrt(tvx * tvx + tvy * tvy + tvz * tvz)
    if vt > 0.0:
        scale = coulomb_friction_scale(f_n, vt, law[LAW_SLIDING], v_reg,
                                       law[LAW_TANGENTIAL_MASS], dt)
        return scale * tvx, scale * tvy, scale * tvz
    return 0.0, 0.0, 0.0


@njit(cache=True, inline="always")
def _contact(hist, a, b, law, nx, ny, nz, delta, arm,
             rvx, rvy, rvz, hpx, hpy, hpz, dsx, dsy, dsz,
             rox, roy, roz, ropx, ropy, ropz, options, rolling):
    """Forces of one contact (pair or wall) on its first particle i; updates its history.

    ``n`` unit normal from i to the partner, ``delta`` overlap, ``arm`` centre to contact
    point. ``rv``: predicted relative velocity of the centres, v_i - v_partner; ``hp``: the
    predicted angular velocity that moves the contact point tangentially (omega_i + omega_j
    for a pair, omega_i at a wall); ``ds``: tangential displacement of the
    contact points over the step; ``ro``/``rop``: relative rotation over the step, (omega_i -
    omega_j) dt with drift velocities, and the predicted relative angular velocity.
    ``options``: (clip_attraction, stick_slip, v_reg, dt) (Numba inlines at most 30
    arguments); ``rolling``: whether any pair has rolling resistance.

    Code size of the hot loop is speed here (unused branches inlined into it cost the
    resting bed ~25 %): ``rolling`` is a compile-time constant (:func:`numba.literally` in
    :func:`_cell_steps`, which :func:`advance_cells` calls with a constant True or False,
    so a call from Python pays no literal dispatch: ~0.1 ms instead of ~12 ms), and the
    Coulomb law, off by default, is called out of line (:func:`_coulomb_force`).

    Returns (f_el, f_n, gx, gy, gz, mx, my, mz, mdx, mdy, mdz, lost_t, lost_r): the Hertz and
    total normal force, the tangential force on i, the rolling torque on i (spring and
    dashpot; the partner gets the opposite) and its dashpot part alone, and the energy the
    springs lost this step (friction, rolling), J.
    """
    clip_attraction = options[0]
    delta_dot = rvx * nx + rvy * ny + rvz * nz
    f_el, f_n = hertz_normal_force(delta, delta_dot, law[LAW_STIFFNESS], law[LAW_DAMPING],
                                   clip_attraction)
    lost_t = 0.0
    k_t = mindlin_tangential_stiffness(delta, law[LAW_TANGENTIAL_STIFFNESS],
                                       law[LAW_MINDLIN_FACTOR])
    if options[1]:
        k_old = k_t
        if law[LAW_MINDLIN_FACTOR] > 0.0:
            k_old = hist[a, b, HIST_KT]
        sliding = hist[a, b, HIST_SLIDING] != 0.0
        fa = abs(f_n)
        sx, sy, sz, lost_t, slides = capped_spring(
            hist[a, b, 0], hist[a, b, 1], hist[a, b, 2], dsx, dsy, dsz, nx, ny, nz,
            k_t, k_old, law[LAW_STATIC] * fa, law[LAW_SLIDING] * fa, sliding)
        hist[a, b, 0] = sx
        hist[a, b, 1] = sy
        hist[a, b, 2] = sz
        hist[a, b, HIST_SLIDING] = 1.0 if slides else 0.0
        gx = -k_t * sx
        gy = -k_t * sy
        gz = -k_t * sz
    else:
        gx, gy, gz = _coulomb_force(law, nx, ny, nz, arm, rvx, rvy, rvz, hpx, hpy, hpz,
                                    delta_dot, f_n, options[2], options[3])
    hist[a, b, HIST_KT] = k_t
    mx = 0.0
    my = 0.0
    mz = 0.0
    mdx = 0.0
    mdy = 0.0
    mdz = 0.0
    lost_r = 0.0
    k_r = law[LAW_ROLLING_STIFFNESS]
    if rolling and k_r > 0.0:
        cap = law[LAW_ROLLING_ARM] * abs(f_n)
        qx, qy, qz, lost_r, rolls = capped_spring(
            hist[a, b, HIST_ROLL], hist[a, b, HIST_ROLL + 1], hist[a, b, HIST_ROLL + 2],
            rox, roy, roz, nx, ny, nz, k_r, k_r, cap, cap, False)
        hist[a, b, HIST_ROLL] = qx
        hist[a, b, HIST_ROLL + 1] = qy
        hist[a, b, HIST_ROLL + 2] = qz
        mx = -k_r * qx
        my = -k_r * qy
        mz = -k_r * qz
        c_r = law[LAW_ROLLING_DAMPING]
        if c_r > 0.0 and not rolls:
            # dashpot on the tangent-plane part of the relative angular velocity
            wn = ropx * nx + ropy * ny + ropz * nz
            mdx = -c_r * (ropx - wn * nx)
            mdy = -c_r * (ropy - wn * ny)
            mdz = -c_r * (ropz - wn * nz)
            mx += mdx
            my += mdy
            mz += mdz
    return f_el, f_n, gx, gy, gz, mx, my, mz, mdx, mdy, mdz, lost_t, lost_r


@njit(cache=True, inline="always")
def _half_kick(i, half_dt, vx, vy, vz, ox, oy, oz, fx, fy, fz, tx, ty, tz, inv_m, inv_i):
    """Half a velocity-Verlet kick of particle i by its force and torque (``half_dt`` = dt/2)."""
    vx[i] += half_dt * fx[i] * inv_m
    vy[i] += half_dt * fy[i] * inv_m
    vz[i] += half_dt * fz[i] * inv_m
    ox[i] += half_dt * tx[i] * inv_i
    oy[i] += half_dt * ty[i] * inv_i
    oz[i] += half_dt * tz[i] * inv_i


@njit(cache=True, inline="always")
def _contact_force(f_n, nx, ny, nz, gx, gy, gz, arm):
    """Force -f_n n + g of a contact on its first particle and the torque arm n x g of g."""
    return (-f_n * nx + gx, -f_n * ny + gy, -f_n * nz + gz,
            arm * (ny * gz - nz * gy), arm * (nz * gx - nx * gz), arm * (nx * gy - ny * gx))


@njit(cache=True, inline="always")
def _record_contact(c_idx, c_val, k, i, j, nx, ny, nz, arm, f_damping, gx, gy, gz,
                    mdx, mdy, mdz):
    """Keep contact ``k`` (partner j, -1 for a wall) for the dissipation tally after the kick."""
    c_idx[0, k] = i
    c_idx[1, k] = j
    c_val[0, k] = nx
    c_val[1, k] = ny
    c_val[2, k] = nz
    c_val[3, k] = arm
    c_val[4, k] = f_damping
    c_val[5, k] = gx
    c_val[6, k] = gy
    c_val[7, k] = gz
    c_val[8, k] = mdx
    c_val[9, k] = mdy
    c_val[10, k] = mdz


@njit(cache=True, nogil=True)
def advance_cells(pos, vel, omg, frc, trq, wall_n, wall_d,
                  radius, mass, inertia, law_pp, law_pw,
                  v_reg, clip_attraction, gravity, stick_slip, rolling, hist_pp, hist_pw,
                  dt, step0, n_steps, omega, accel_amp, drive_axis,
                  steps_per_cycle, sample_every, max_overlap_fraction,
                  tally, samples, status, fail_step, first_cell, end_cell):
    # rolling resistance as a compile-time constant: two machine codes, the one without
    # rolling free of its code (smaller hot loop); chosen here, per call, at no dispatch
    # cost. The one with it runs without reference counting on work arrays allocated here
    # (see _cell_steps).
    args = (pos, vel, omg, frc, trq, wall_n, wall_d, radius, mass, inertia, law_pp, law_pw,
            v_reg, clip_attraction, gravity, stick_slip, hist_pp, hist_pw,
            dt, step0, n_steps, omega, accel_amp, drive_axis,
            steps_per_cycle, sample_every, max_overlap_fraction,
            tally, samples, status, fail_step)
    for c in range(first_cell, end_cell):
        if status[c] != STATUS_OK:
            continue
        if rolling:
            _advance_cell_rolling(True, c, args, _cell_work(c, args))
        else:
            _advance_cell(False, c, args, None)
    return 0


@njit(cache=True, inline="always")
def _cell_work(c, args):
    """Contiguous copies of cell ``c``'s state and the work arrays of :func:`_cell_steps`
    (``args`` as there), as one tuple."""
    (pos, vel, omg, frc, trq, wall_n, wall_d, radius, mass, inertia, law_pp, law_pw,
     v_reg, clip_attraction, gravity, stick_slip, hist_pp, hist_pw,
     dt, step0, n_steps, omega, accel_amp, drive_axis,
     steps_per_cycle, sample_every, max_overlap_fraction,
     tally, samples, status, fail_step) = args
    n_part = pos.shape[2]
    n_walls = wall_n.shape[0]
    max_pairs = n_part * (n_part - 1) // 2
    max_contacts = n_walls * n_part + max_pairs
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
    # contact histories: [i, j] for pairs i < j, [i, wall] for walls
    hp = hist_pp[c].copy()
    hw = hist_pw[c].copy()
    # contacts of the step for the dissipation tally: i, j (j < 0: wall); n (3), arm,
    # f_damping, friction force (3), rolling dashpot torque on i (3)
    c_idx = np.empty((2, max_contacts), dtype=np.int64)
    c_val = np.empty((11, max_contacts))
    # Verlet lists: pair candidates (i < j, brute-force order), wall candidates per particle
    nb_i = np.empty(max_pairs, dtype=np.int64)
    nb_j = np.empty(max_pairs, dtype=np.int64)
    wl_start = np.empty(n_part + 1, dtype=np.int64)
    wl_w = np.empty(n_walls * n_part, dtype=np.int64)
    ref_x = np.empty(n_part)  # positions at the last build (absolute)
    ref_y = np.empty(n_part)
    ref_z = np.empty(n_part)
    return (px, py, pz, vx, vy, vz, ox, oy, oz, fx, fy, fz, tx, ty, tz,
            vpx, vpy, vpz, wpx, wpy, wpz, wnx, wny, wnz, wd, hp, hw,
            c_idx, c_val, nb_i, nb_j, wl_start, wl_w, ref_x, ref_y, ref_z)


def _work_of(c, args, work):
    """The work arrays of :func:`_cell_steps`: allocated here (:func:`_cell_work`) when
    ``work`` is None, else ``work`` itself. Compiled code only: chosen by the type of
    ``work`` as the code is compiled (:func:`_work_of_overload`), so that the machine code
    without reference counting holds no allocation."""
    raise NotImplementedError("compiled code only")


@overload(_work_of, inline="always", jit_options={"cache": True})
def _work_of_overload(c, args, work):
    """Numba's implementation of :func:`_work_of` for the type of ``work``."""
    if isinstance(work, types.NoneType):
        def allocate(c, args, work):
            return _cell_work(c, args)
        return allocate

    def given(c, args, work):
        return work
    return given


def _cell_steps(rolling, c, args, work):
    """Advance cell ``c`` by ``n_steps`` (see the module docstring); ``args`` are
    :func:`advance_cells`'s arguments from ``pos`` to ``fail_step`` but ``rolling``;
    ``work``: the cell's work arrays (:func:`_cell_work`), or None to allocate them here.

    Compiled twice from this one source: :data:`_advance_cell` for the machine code without
    rolling resistance (``work`` None: the arrays it allocates itself are known not to
    alias, which its speed depends on) and :data:`_advance_cell_rolling` for the code with
    it, compiled without Numba's reference counting (``_nrt=False``; the caller allocates
    ``work``). In the larger rolling code, Numba left an atomic increment and decrement of
    the reference count around every contact for each array passed into the inlined
    contact body (its refcount pruning gives up on large functions); without reference
    counting there are none: 10-15 % faster on the rolling beds, the same bits.

    Speed (results are bit-identical to a brute-force search over all pairs and walls):
    the cell's state is copied into contiguous 1-D arrays for the chunk; particle pairs
    and particle-wall pairs come from Verlet lists (candidates within contact + skin, kept
    in the brute-force order i < j, walls ascending, so forces are summed in the same order)
    rebuilt whenever a particle has moved skin/2 since the last build (relative to the
    cell for the walls, which move with it).
    """
    literally(rolling)
    (pos, vel, omg, frc, trq, wall_n, wall_d, radius, mass, inertia, law_pp, law_pw,
     v_reg, clip_attraction, gravity, stick_slip, hist_pp, hist_pw,
     dt, step0, n_steps, omega, accel_amp, drive_axis,
     steps_per_cycle, sample_every, max_overlap_fraction,
     tally, samples, status, fail_step) = args
    n_part = pos.shape[2]
    n_walls = wall_n.shape[0]
    inv_m = 1.0 / mass
    inv_i = 1.0 / inertia
    half_dt = 0.5 * dt
    two_r = 2.0 * radius
    max_overlap = max_overlap_fraction * radius
    skin = NEIGHBOUR_SKIN_FRACTION * radius
    half_skin2 = 0.25 * skin * skin
    pair_reach2 = (two_r + skin) * (two_r + skin)
    wall_reach = radius + skin
    kr_pp = law_pp[LAW_ROLLING_STIFFNESS]
    kr_pw = law_pw[LAW_ROLLING_STIFFNESS]
    # the rolling dashpot's loss is tallied after the second kick, like normal damping
    roll_dashpot = rolling and (law_pp[LAW_ROLLING_DAMPING] > 0.0
                                or law_pw[LAW_ROLLING_DAMPING] > 0.0)
    options = (clip_attraction, stick_slip, v_reg, dt)
    # the cell's state as contiguous copies (written back at the end of the chunk) and the
    # work arrays (_cell_work)
    (px, py, pz, vx, vy, vz, ox, oy, oz, fx, fy, fz, tx, ty, tz,
     vpx, vpy, vpz, wpx, wpy, wpz, wnx, wny, wnz, wd, hp, hw,
     c_idx, c_val, nb_i, nb_j, wl_start, wl_w, ref_x, ref_y, ref_z) = _work_of(c, args, work)
    u_prev = 0.0  # cell displacement along the drive axis at the previous step
    if omega > 0.0:
        t_prev = step0 * dt  # same rounding as t below, so chunking does not change bits
        u_prev = -accel_amp / (omega * omega) * np.sin(omega * t_prev)
    n_nb = 0
    ref_ux = 0.0  # cell displacement at the last build
    ref_uy = 0.0
    ref_uz = 0.0
    rebuild = True
    for s in range(n_steps):
        # --- first half kick and drift -------------------------------------------------
        for i in range(n_part):
            _half_kick(i, half_dt, vx, vy, vz, ox, oy, oz, fx, fy, fz, tx, ty, tz, inv_m, inv_i)
            px[i] += dt * vx[i]
            py[i] += dt * vy[i]
            pz[i] += dt * vz[i]
            vpx[i] = vx[i] + half_dt * fx[i] * inv_m
            vpy[i] = vy[i] + half_dt * fy[i] * inv_m
            vpz[i] = vz[i] + half_dt * fz[i] * inv_m
            wpx[i] = ox[i] + half_dt * tx[i] * inv_i
            wpy[i] = oy[i] + half_dt * ty[i] * inv_i
            wpz[i] = oz[i] + half_dt * tz[i] * inv_i
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
        d_roll = 0.0
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
                dist = wnx[w] * (pxi - ux) + wny[w] * (pyi - uy) + wnz[w] * (pzi - uz) + wd[w]
                delta = radius - dist
                if delta <= 0.0:
                    lt, lr = _release(hw, i, w, kr_pw)
                    d_fric += lt
                    d_roll += lr
                    continue
                if dist < 0.0:
                    status[c] = STATUS_ESCAPED
                if delta > max_overlap:
                    status[c] = STATUS_OVERLAP
                # normal from the particle towards the wall
                nx = -wnx[w]
                ny = -wny[w]
                nz = -wnz[w]
                arm = radius - delta
                oxi = ox[i]
                oyi = oy[i]
                ozi = oz[i]
                f_el, f_n, gx, gy, gz, mx, my, mz, mdx, mdy, mdz, lt, lr = _contact(
                    hw, i, w, law_pw, nx, ny, nz, delta, arm,
                    vpx[i] - wvx, vpy[i] - wvy, vpz[i] - wvz,
                    wpx[i], wpy[i], wpz[i],
                    # contact-point displacement relative to the wall over the step, with
                    # the drift (half-step) velocities the positions moved with
                    dt * (vx[i] + arm * (oyi * nz - ozi * ny)) - dwx,
                    dt * (vy[i] + arm * (ozi * nx - oxi * nz)) - dwy,
                    dt * (vz[i] + arm * (oxi * ny - oyi * nx)) - dwz,
                    dt * oxi, dt * oyi, dt * ozi, wpx[i], wpy[i], wpz[i],
                    options, rolling)
                d_fric += lt
                d_roll += lr
                cfx, cfy, cfz, ctx, cty, ctz = _contact_force(f_n, nx, ny, nz, gx, gy, gz,
                                                              arm)
                tx[i] += ctx + mx
                ty[i] += cty + my
                tz[i] += ctz + mz
                fx[i] += cfx
                fy[i] += cfy
                fz[i] += cfz
                _record_contact(c_idx, c_val, n_c, i, -1, nx, ny, nz, arm, f_n - f_el,
                                gx, gy, gz, mdx, mdy, mdz)
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
                lt, lr = _release(hp, i, j, kr_pp)
                d_fric += lt
                d_roll += lr
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
            hx = ox[i] + ox[j]
            hy = oy[i] + oy[j]
            hz = oz[i] + oz[j]
            f_el, f_n, gx, gy, gz, mx, my, mz, mdx, mdy, mdz, lt, lr = _contact(
                hp, i, j, law_pp, nx, ny, nz, delta, arm,
                vpx[i] - vpx[j], vpy[i] - vpy[j], vpz[i] - vpz[j],
                wpx[i] + wpx[j], wpy[i] + wpy[j], wpz[i] + wpz[j],
                dt * (vx[i] - vx[j] + arm * (hy * nz - hz * ny)),
                dt * (vy[i] - vy[j] + arm * (hz * nx - hx * nz)),
                dt * (vz[i] - vz[j] + arm * (hx * ny - hy * nx)),
                dt * (ox[i] - ox[j]), dt * (oy[i] - oy[j]), dt * (oz[i] - oz[j]),
                wpx[i] - wpx[j], wpy[i] - wpy[j], wpz[i] - wpz[j],
                options, rolling)
            d_fric += lt
            d_roll += lr
            # force on i: -f_n n + g, on j the opposite; torque of g: arm n x g on both;
            # rolling torque: m on i, -m on j
            cfx, cfy, cfz, ctx, cty, ctz = _contact_force(f_n, nx, ny, nz, gx, gy, gz, arm)
            tx[i] += ctx + mx
            ty[i] += cty + my
            tz[i] += ctz + mz
            tx[j] += ctx - mx
            ty[j] += cty - my
            tz[j] += ctz - mz
            fx[i] += cfx
            fy[i] += cfy
            fz[i] += cfz
            fx[j] -= cfx
            fy[j] -= cfy
            fz[j] -= cfz
            _record_contact(c_idx, c_val, n_c, i, j, nx, ny, nz, arm, f_n - f_el,
                            gx, gy, gz, mdx, mdy, mdz)
            n_c += 1
        # --- second half kick ----------------------------------------------------------
        for i in range(n_part):
            _half_kick(i, half_dt, vx, vy, vz, ox, oy, oz, fx, fy, fz, tx, ty, tz, inv_m, inv_i)
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
            else:
                rvx = vx[i] - vx[j]
                rvy = vy[i] - vy[j]
                rvz = vz[i] - vz[j]
            delta_dot = rvx * nx + rvy * ny + rvz * nz
            d_norm += c_val[4, q] * delta_dot * dt
            if roll_dashpot:
                wx = ox[i]
                wy = oy[i]
                wz = oz[i]
                if j >= 0:
                    wx -= ox[j]
                    wy -= oy[j]
                    wz -= oz[j]
                d_roll -= (c_val[8, q] * wx + c_val[9, q] * wy + c_val[10, q] * wz) * dt
            if stick_slip:
                continue  # friction loss was tallied where the spring slid
            arm = c_val[3, q]
            sx = ox[i]
            sy = oy[i]
            sz = oz[i]
            if j >= 0:
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
        tally[c, cyc, 3] += d_roll
        samples[c, smp] += f_drive
        if status[c] != STATUS_OK:
            fail_step[c] = step0 + s + 1
            break
    # element loops: a slice assignment compiles a shape-check helper of its own (~0.1 s
    # each, 16 per variant: ~6 s of a cold compile)
    for dst, rows in ((pos, (px, py, pz)), (vel, (vx, vy, vz)), (omg, (ox, oy, oz)),
                      (frc, (fx, fy, fz)), (trq, (tx, ty, tz))):
        for k in range(3):
            row = rows[k]
            for i in range(n_part):
                dst[k, c, i] = row[i]
    for hist, h in ((hist_pp, hp), (hist_pw, hw)):
        for a in range(h.shape[0]):
            for b in range(h.shape[1]):
                for q in range(h.shape[2]):
                    hist[c, a, b, q] = h[a, b, q]


#: :func:`_cell_steps` compiled twice: with Numba's reference counting for the code without
#: rolling resistance (it allocates its work arrays), and without it for the code with
#: rolling resistance, whose work arrays :func:`advance_cells` allocates
_advance_cell = njit(cache=True, error_model="numpy")(_cell_steps)
# _nrt=False is Numba's (underscored) option for code without reference counting, as for
# kernels that get every array from their caller
_advance_cell_rolling = njit(cache=True, error_model="numpy", _nrt=False)(_cell_steps)


@njit(cache=True)
def contact_energy(pos, hist_pp, hist_pw, wall_n, wall_d, offset, radius, law_pp, law_pw):
    """Elastic energy stored in the contacts of each cell, (K,), J.

    Hertz energy of every overlap (:func:`pidcore.dem.contact.hertz_elastic_energy`, the
    potential of the kernel's normal force) plus 1/2 k_t |xi|^2 of the tangential springs
    (each at the k_t it is stored with) and 1/2 k_r |theta|^2 of the rolling springs.
    ``offset`` (3,) is the cell's displacement.
    """
    n_cells = pos.shape[1]
    n_part = pos.shape[2]
    out = np.zeros(n_cells)
    for c in range(n_cells):
        e = 0.0
        for i in range(n_part):
            for w in range(wall_n.shape[0]):
                dist = (wall_n[w, 0] * (pos[0, c, i] - offset[0])
                        + wall_n[w, 1] * (pos[1, c, i] - offset[1])
                        + wall_n[w, 2] * (pos[2, c, i] - offset[2]) + wall_d[w])
                e += hertz_elastic_energy(radius - dist, law_pw[LAW_STIFFNESS])
            for j in range(i + 1, n_part):
                dx = pos[0, c, j] - pos[0, c, i]
                dy = pos[1, c, j] - pos[1, c, i]
                dz = pos[2, c, j] - pos[2, c, i]
                d = np.sqrt(dx * dx + dy * dy + dz * dz)
                e += hertz_elastic_energy(2.0 * radius - d, law_pp[LAW_STIFFNESS])
        for hist, law in ((hist_pp, law_pp), (hist_pw, law_pw)):
            k_r = law[LAW_ROLLING_STIFFNESS]
            for a in range(hist.shape[1]):
                for b in range(hist.shape[2]):
                    h = hist[c, a, b]
                    e += 0.5 * h[HIST_KT] * (h[0] * h[0] + h[1] * h[1] + h[2] * h[2])
                    if k_r > 0.0:
                        e += 0.5 * k_r * (h[HIST_ROLL] ** 2 + h[HIST_ROLL + 1] ** 2
                                          + h[HIST_ROLL + 2] ** 2)
        out[c] = e
    return out
