/* Straight C translation of pidcore/dem/kernel.py (advance_cells -> _advance_cell), for
 * measurement only. Same operations, same order, same array layouts as the Numba kernel.
 * `rolling` is a compile-time constant: advance_cell_impl is always_inline and is
 * instantiated twice (advance_cell_roll / advance_cell_noroll).
 * Build: gcc -O3 -march=native -ffp-contract=off -fPIC -shared -o libck.so ckernel.c -lm
 * Optional: -DNO_ROLLING_CODE compiles the rolling law out of the rolling=1 variant too
 * (diagnostic only: results then differ for beds with rolling friction).
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define LAW_STIFFNESS 0
#define LAW_DAMPING 1
#define LAW_SLIDING 2
#define LAW_STATIC 3
#define LAW_TANGENTIAL_MASS 4
#define LAW_TANGENTIAL_STIFFNESS 5
#define LAW_MINDLIN_FACTOR 6
#define LAW_ROLLING_STIFFNESS 7
#define LAW_ROLLING_ARM 8
#define LAW_ROLLING_DAMPING 9

#define HIST_SLIDING 3
#define HIST_KT 4
#define HIST_ROLL 5
#define NH 8

#define STATUS_OK 0
#define STATUS_OVERLAP 1
#define STATUS_ESCAPED 2
#define STATUS_NONFINITE 3

#define NEIGHBOUR_SKIN_FRACTION 0.3

#define INLINE static inline __attribute__((always_inline))

#ifdef COUNT
/* diagnostic counters: steps, rebuilds, wall candidates, wall contacts, pair candidates,
 * pair contacts, tangential springs sliding, rolling springs at cap */
int64_t ck_counts[8];
#define CNT(k) (ck_counts[k]++)
#define CNTN(k, n) (ck_counts[k] += (n))
#else
#define CNT(k)
#define CNTN(k, n)
#endif

/* _release: contact open, clear history; returns energies via pointers */
INLINE void release(double *h, double k_r, double *held_t_out, double *held_r_out)
{
    double k_t = h[HIST_KT];
    if (k_t == 0.0) {
        *held_t_out = 0.0;
        *held_r_out = 0.0;
        return;
    }
    double held_t = 0.5 * k_t * (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
    double held_r = 0.0;
    if (k_r > 0.0) {
        held_r = 0.5 * k_r * (h[HIST_ROLL] * h[HIST_ROLL] + h[HIST_ROLL + 1] * h[HIST_ROLL + 1]
                              + h[HIST_ROLL + 2] * h[HIST_ROLL + 2]);
    }
    for (int q = 0; q < NH; q++)
        h[q] = 0.0;
    *held_t_out = held_t;
    *held_r_out = held_r;
}

/* contact.capped_spring */
INLINE void capped_spring(double sx, double sy, double sz, double dsx, double dsy, double dsz,
                          double nx, double ny, double nz, double k, double k_old,
                          double stick_limit, double slide_limit, int sliding,
                          double *oax, double *oay, double *oaz, double *olost, int *oslides)
{
    double sn = sx * nx + sy * ny + sz * nz;
    sx -= sn * nx;
    sy -= sn * ny;
    sz -= sn * nz;
    double lost = 0.5 * k_old * sn * sn;
    double old2 = sx * sx + sy * sy + sz * sz;
    if (k != k_old) {
        double held = 0.5 * k_old * old2;
        if (k > k_old) {
            double scale = k_old / k;
            sx *= scale;
            sy *= scale;
            sz *= scale;
            old2 = sx * sx + sy * sy + sz * sz;
        }
        lost += held - 0.5 * k * old2;
    }
    double dn = dsx * nx + dsy * ny + dsz * nz;
    dsx -= dn * nx;
    dsy -= dn * ny;
    dsz -= dn * nz;
    double ax = sx + dsx;
    double ay = sy + dsy;
    double az = sz + dsz;
    double trial2 = ax * ax + ay * ay + az * az;
    double limit = sliding ? slide_limit : stick_limit;
    int slides = 0;
    if (k * k * trial2 > limit * limit) {
        double keep = slide_limit / (k * sqrt(trial2));
        ax *= keep;
        ay *= keep;
        az *= keep;
        double work = 0.5 * k * ((sx + ax) * dsx + (sy + ay) * dsy + (sz + az) * dsz);
        double gained = 0.5 * k * (ax * ax + ay * ay + az * az - old2);
        lost = lost + work - gained;
        slides = 1;
    }
    *oax = ax;
    *oay = ay;
    *oaz = az;
    *olost = lost;
    *oslides = slides;
}

/* _coulomb_force (out of line, as in Numba) */
static __attribute__((noinline)) void coulomb_force(
    const double *law, double nx, double ny, double nz, double arm, double rvx, double rvy,
    double rvz, double hpx, double hpy, double hpz, double delta_dot, double f_n,
    double v_reg, double dt, double *gx, double *gy, double *gz)
{
    double tvx = rvx + arm * (hpy * nz - hpz * ny);
    double tvy = rvy + arm * (hpz * nx - hpx * nz);
    double tvz = rvz + arm * (hpx * ny - hpy * nx);
    tvx -= delta_dot * nx;
    tvy -= delta_dot * ny;
    tvz -= delta_dot * nz;
    double vt = sqrt(tvx * tvx + tvy * tvy + tvz * tvz);
    if (vt > 0.0) {
        /* coulomb_friction_scale */
        double ft = law[LAW_SLIDING] * fabs(f_n);
        if (vt < v_reg)
            ft *= vt / v_reg;
        double cap = 0.5 * law[LAW_TANGENTIAL_MASS] * vt / dt;
        if (ft > cap)
            ft = cap;
        double scale = -ft / vt;
        *gx = scale * tvx;
        *gy = scale * tvy;
        *gz = scale * tvz;
        return;
    }
    *gx = 0.0;
    *gy = 0.0;
    *gz = 0.0;
}

typedef struct {
    double f_el, f_n, gx, gy, gz, mx, my, mz, mdx, mdy, mdz, lost_t, lost_r;
} ContactOut;

/* _contact: h points at hist[a, b, :] */
INLINE void contact(double *h, const double *law, double nx, double ny, double nz,
                    double delta, double arm, double rvx, double rvy, double rvz,
                    double hpx, double hpy, double hpz, double dsx, double dsy, double dsz,
                    double rox, double roy, double roz, double ropx, double ropy, double ropz,
                    int clip_attraction, int stick_slip, double v_reg, double dt,
                    const int rolling, ContactOut *o)
{
    double delta_dot = rvx * nx + rvy * ny + rvz * nz;
    /* hertz_normal_force */
    double sq = sqrt(delta);
    double f_el = law[LAW_STIFFNESS] * delta * sq;
    double f_n = f_el + law[LAW_DAMPING] * sqrt(sq) * delta_dot;
    if (clip_attraction && f_n < 0.0)
        f_n = 0.0;
    double lost_t = 0.0;
    /* mindlin_tangential_stiffness */
    double k_t;
    if (law[LAW_MINDLIN_FACTOR] > 0.0)
        k_t = law[LAW_MINDLIN_FACTOR] * sqrt(delta);
    else
        k_t = law[LAW_TANGENTIAL_STIFFNESS];
    double gx, gy, gz;
    if (stick_slip) {
        double k_old = k_t;
        if (law[LAW_MINDLIN_FACTOR] > 0.0)
            k_old = h[HIST_KT];
        int sliding = h[HIST_SLIDING] != 0.0;
        double fa = fabs(f_n);
        double sx, sy, sz;
        int slides;
        capped_spring(h[0], h[1], h[2], dsx, dsy, dsz, nx, ny, nz, k_t, k_old,
                      law[LAW_STATIC] * fa, law[LAW_SLIDING] * fa, sliding,
                      &sx, &sy, &sz, &lost_t, &slides);
        h[0] = sx;
        h[1] = sy;
        h[2] = sz;
        h[HIST_SLIDING] = slides ? 1.0 : 0.0;
        if (slides) CNT(6);
        gx = -k_t * sx;
        gy = -k_t * sy;
        gz = -k_t * sz;
    } else {
        coulomb_force(law, nx, ny, nz, arm, rvx, rvy, rvz, hpx, hpy, hpz, delta_dot, f_n,
                      v_reg, dt, &gx, &gy, &gz);
    }
    h[HIST_KT] = k_t;
    double mx = 0.0, my = 0.0, mz = 0.0, mdx = 0.0, mdy = 0.0, mdz = 0.0;
    double lost_r = 0.0;
    double k_r = law[LAW_ROLLING_STIFFNESS];
#ifndef NO_ROLLING_CODE
    if (rolling && k_r > 0.0) {
        double cap = law[LAW_ROLLING_ARM] * fabs(f_n);
        double qx, qy, qz;
        int rolls;
        capped_spring(h[HIST_ROLL], h[HIST_ROLL + 1], h[HIST_ROLL + 2], rox, roy, roz,
                      nx, ny, nz, k_r, k_r, cap, cap, 0, &qx, &qy, &qz, &lost_r, &rolls);
        h[HIST_ROLL] = qx;
        h[HIST_ROLL + 1] = qy;
        h[HIST_ROLL + 2] = qz;
        if (rolls) CNT(7);
        mx = -k_r * qx;
        my = -k_r * qy;
        mz = -k_r * qz;
        double c_r = law[LAW_ROLLING_DAMPING];
        if (c_r > 0.0 && !rolls) {
            double wn = ropx * nx + ropy * ny + ropz * nz;
            mdx = -c_r * (ropx - wn * nx);
            mdy = -c_r * (ropy - wn * ny);
            mdz = -c_r * (ropz - wn * nz);
            mx += mdx;
            my += mdy;
            mz += mdz;
        }
    }
#else
    (void)k_r; (void)rox; (void)roy; (void)roz; (void)ropx; (void)ropy; (void)ropz;
#endif
    o->f_el = f_el;
    o->f_n = f_n;
    o->gx = gx;
    o->gy = gy;
    o->gz = gz;
    o->mx = mx;
    o->my = my;
    o->mz = mz;
    o->mdx = mdx;
    o->mdy = mdy;
    o->mdz = mdz;
    o->lost_t = lost_t;
    o->lost_r = lost_r;
}

typedef struct {
    double *pos, *vel, *omg, *frc, *trq; /* (3, K, N) */
    const double *wall_n, *wall_d;       /* (W, 3), (W,) */
    double radius, mass, inertia;
    const double *law_pp, *law_pw; /* (10,) */
    double v_reg;
    int64_t clip_attraction;
    double gravity;
    int64_t stick_slip;
    double *hist_pp, *hist_pw; /* (K, N, N, 8), (K, N, W, 8) */
    double dt;
    int64_t step0, n_steps;
    double omega, accel_amp;
    int64_t drive_axis, steps_per_cycle, sample_every;
    double max_overlap_fraction;
    double *tally;   /* (K, n_cyc, 4) */
    double *samples; /* (K, n_smp) */
    int64_t *status, *fail_step;
    int64_t K, N, W, n_cyc, n_smp;
} Args;

INLINE void advance_cell_impl(const int rolling, int64_t c, const Args *A)
{
    const int64_t n_part = A->N;
    const int64_t n_walls = A->W;
    const int64_t K = A->K;
    const double radius = A->radius, mass = A->mass, dt = A->dt, gravity = A->gravity;
    const double *law_pp = A->law_pp, *law_pw = A->law_pw;
    const int64_t step0 = A->step0, n_steps = A->n_steps, drive_axis = A->drive_axis;
    const double omega = A->omega, accel_amp = A->accel_amp;
    const int clip_attraction = A->clip_attraction != 0;
    const int stick_slip = A->stick_slip != 0;
    const double v_reg = A->v_reg;
    int64_t *status = A->status;
    double inv_m = 1.0 / mass;
    double inv_i = 1.0 / A->inertia;
    double half_dt = 0.5 * dt;
    double two_r = 2.0 * radius;
    double max_overlap = A->max_overlap_fraction * radius;
    double skin = NEIGHBOUR_SKIN_FRACTION * radius;
    double half_skin2 = 0.25 * skin * skin;
    double pair_reach2 = (two_r + skin) * (two_r + skin);
    double wall_reach = radius + skin;
    double kr_pp = law_pp[LAW_ROLLING_STIFFNESS];
    double kr_pw = law_pw[LAW_ROLLING_STIFFNESS];
    int roll_dashpot = rolling && (law_pp[LAW_ROLLING_DAMPING] > 0.0
                                   || law_pw[LAW_ROLLING_DAMPING] > 0.0);

    /* contiguous per-cell copies */
    double *buf = malloc(sizeof(double) * 21 * n_part);
    double *px = buf, *py = buf + n_part, *pz = buf + 2 * n_part;
    double *vx = buf + 3 * n_part, *vy = buf + 4 * n_part, *vz = buf + 5 * n_part;
    double *ox = buf + 6 * n_part, *oy = buf + 7 * n_part, *oz = buf + 8 * n_part;
    double *fx = buf + 9 * n_part, *fy = buf + 10 * n_part, *fz = buf + 11 * n_part;
    double *tx = buf + 12 * n_part, *ty = buf + 13 * n_part, *tz = buf + 14 * n_part;
    double *vpx = buf + 15 * n_part, *vpy = buf + 16 * n_part, *vpz = buf + 17 * n_part;
    double *wpx = buf + 18 * n_part, *wpy = buf + 19 * n_part, *wpz = buf + 20 * n_part;
    double *rows[5] = {A->pos, A->vel, A->omg, A->frc, A->trq};
    for (int a = 0; a < 5; a++)
        for (int k = 0; k < 3; k++)
            memcpy(buf + (3 * a + k) * n_part, rows[a] + (k * K + c) * n_part,
                   sizeof(double) * n_part);
    double *wnx = malloc(sizeof(double) * 4 * n_walls);
    double *wny = wnx + n_walls, *wnz = wnx + 2 * n_walls, *wd = wnx + 3 * n_walls;
    for (int64_t w = 0; w < n_walls; w++) {
        wnx[w] = A->wall_n[3 * w];
        wny[w] = A->wall_n[3 * w + 1];
        wnz[w] = A->wall_n[3 * w + 2];
        wd[w] = A->wall_d[w];
    }
    const int64_t hp_size = n_part * n_part * NH, hw_size = n_part * n_walls * NH;
    double *hp = malloc(sizeof(double) * (hp_size + hw_size));
    double *hw = hp + hp_size;
    memcpy(hp, A->hist_pp + c * hp_size, sizeof(double) * hp_size);
    memcpy(hw, A->hist_pw + c * hw_size, sizeof(double) * hw_size);
    double u_prev = 0.0;
    if (omega > 0.0) {
        double t_prev = (double)step0 * dt;
        u_prev = -accel_amp / (omega * omega) * sin(omega * t_prev);
    }
    int64_t max_pairs = n_part * (n_part - 1) / 2;
    int64_t max_contacts = n_walls * n_part + max_pairs;
    int64_t *c_idx = malloc(sizeof(int64_t) * 2 * max_contacts);
    double *c_val = malloc(sizeof(double) * 11 * max_contacts);
#define CIDX(r, k) c_idx[(r) * max_contacts + (k)]
#define CVAL(r, k) c_val[(r) * max_contacts + (k)]
    int64_t *nb_i = malloc(sizeof(int64_t) * (2 * max_pairs + n_part + 1 + n_walls * n_part));
    int64_t *nb_j = nb_i + max_pairs;
    int64_t n_nb = 0;
    int64_t *wl_start = nb_j + max_pairs;
    int64_t *wl_w = wl_start + n_part + 1;
    double *ref_x = malloc(sizeof(double) * 3 * n_part);
    double *ref_y = ref_x + n_part, *ref_z = ref_x + 2 * n_part;
    double ref_ux = 0.0, ref_uy = 0.0, ref_uz = 0.0;
    int rebuild = 1;
    ContactOut co;
    for (int64_t s = 0; s < n_steps; s++) {
        /* first half kick and drift */
        for (int64_t i = 0; i < n_part; i++) {
            vx[i] += half_dt * fx[i] * inv_m;
            vy[i] += half_dt * fy[i] * inv_m;
            vz[i] += half_dt * fz[i] * inv_m;
            ox[i] += half_dt * tx[i] * inv_i;
            oy[i] += half_dt * ty[i] * inv_i;
            oz[i] += half_dt * tz[i] * inv_i;
            px[i] += dt * vx[i];
            py[i] += dt * vy[i];
            pz[i] += dt * vz[i];
            vpx[i] = vx[i] + half_dt * fx[i] * inv_m;
            vpy[i] = vy[i] + half_dt * fy[i] * inv_m;
            vpz[i] = vz[i] + half_dt * fz[i] * inv_m;
            wpx[i] = ox[i] + half_dt * tx[i] * inv_i;
            wpy[i] = oy[i] + half_dt * ty[i] * inv_i;
            wpz[i] = oz[i] + half_dt * tz[i] * inv_i;
            fx[i] = 0.0;
            fy[i] = 0.0;
            fz[i] = -mass * gravity;
            tx[i] = 0.0;
            ty[i] = 0.0;
            tz[i] = 0.0;
        }
        /* wall motion at the new time */
        double t = (double)(step0 + s + 1) * dt;
        double u = 0.0, uv = 0.0;
        if (omega > 0.0) {
            u = -accel_amp / (omega * omega) * sin(omega * t);
            uv = -accel_amp / omega * cos(omega * t);
        }
        double ux = 0.0, uy = 0.0, uz = 0.0, wvx = 0.0, wvy = 0.0, wvz = 0.0;
        double dwx = 0.0, dwy = 0.0, dwz = 0.0;
        if (drive_axis == 0) {
            ux = u;
            wvx = uv;
            dwx = u - u_prev;
        } else if (drive_axis == 1) {
            uy = u;
            wvy = uv;
            dwy = u - u_prev;
        } else {
            uz = u;
            wvz = uv;
            dwz = u - u_prev;
        }
        u_prev = u;
        /* Verlet lists */
        if (!rebuild) {
            double dux = ux - ref_ux, duy = uy - ref_uy, duz = uz - ref_uz;
            for (int64_t i = 0; i < n_part; i++) {
                double ax = px[i] - ref_x[i];
                double ay = py[i] - ref_y[i];
                double az = pz[i] - ref_z[i];
                if (ax * ax + ay * ay + az * az >= half_skin2) {
                    rebuild = 1;
                    break;
                }
                ax -= dux;
                ay -= duy;
                az -= duz;
                if (ax * ax + ay * ay + az * az >= half_skin2) {
                    rebuild = 1;
                    break;
                }
            }
        }
        CNT(0);
        if (rebuild) {
            CNT(1);
            rebuild = 0;
            ref_ux = ux;
            ref_uy = uy;
            ref_uz = uz;
            n_nb = 0;
            int64_t n_wl = 0;
            for (int64_t i = 0; i < n_part; i++) {
                ref_x[i] = px[i];
                ref_y[i] = py[i];
                ref_z[i] = pz[i];
                wl_start[i] = n_wl;
                for (int64_t w = 0; w < n_walls; w++) {
                    double dist = (wnx[w] * (px[i] - ux) + wny[w] * (py[i] - uy)
                                   + wnz[w] * (pz[i] - uz) + wd[w]);
                    if (!(dist >= wall_reach)) {
                        wl_w[n_wl] = w;
                        n_wl++;
                    }
                }
                for (int64_t j = i + 1; j < n_part; j++) {
                    double dx = px[j] - px[i];
                    double dy = py[j] - py[i];
                    double dz = pz[j] - pz[i];
                    if (!(dx * dx + dy * dy + dz * dz >= pair_reach2)) {
                        nb_i[n_nb] = i;
                        nb_j[n_nb] = j;
                        n_nb++;
                    }
                }
            }
            wl_start[n_part] = n_wl;
        }
        int64_t cyc = s / A->steps_per_cycle;
        int64_t smp = s / A->sample_every;
        double w_wall = 0.0, d_norm = 0.0, d_fric = 0.0, d_roll = 0.0, f_drive = 0.0;
        int64_t n_c = 0;
        /* particle-wall contacts */
        for (int64_t i = 0; i < n_part; i++) {
            double pxi = px[i], pyi = py[i], pzi = pz[i];
            if (!(isfinite(pxi) && isfinite(pyi) && isfinite(pzi)))
                status[c] = STATUS_NONFINITE;
            for (int64_t q = wl_start[i]; q < wl_start[i + 1]; q++) {
                int64_t w = wl_w[q];
                double dist = wnx[w] * (pxi - ux) + wny[w] * (pyi - uy) + wnz[w] * (pzi - uz)
                              + wd[w];
                double delta = radius - dist;
                double *h = hw + (i * n_walls + w) * NH;
                if (delta <= 0.0) {
                    double lt, lr;
                    release(h, kr_pw, &lt, &lr);
                    d_fric += lt;
                    d_roll += lr;
                    continue;
                }
                if (dist < 0.0)
                    status[c] = STATUS_ESCAPED;
                if (delta > max_overlap)
                    status[c] = STATUS_OVERLAP;
                double nx = -wnx[w], ny = -wny[w], nz = -wnz[w];
                double arm = radius - delta;
                double oxi = ox[i], oyi = oy[i], ozi = oz[i];
                contact(h, law_pw, nx, ny, nz, delta, arm,
                        vpx[i] - wvx, vpy[i] - wvy, vpz[i] - wvz,
                        wpx[i], wpy[i], wpz[i],
                        dt * (vx[i] + arm * (oyi * nz - ozi * ny)) - dwx,
                        dt * (vy[i] + arm * (ozi * nx - oxi * nz)) - dwy,
                        dt * (vz[i] + arm * (oxi * ny - oyi * nx)) - dwz,
                        dt * oxi, dt * oyi, dt * ozi, wpx[i], wpy[i], wpz[i],
                        clip_attraction, stick_slip, v_reg, dt, rolling, &co);
                d_fric += co.lost_t;
                d_roll += co.lost_r;
                double f_n = co.f_n, gx = co.gx, gy = co.gy, gz = co.gz;
                double cfx = -f_n * nx + gx, cfy = -f_n * ny + gy, cfz = -f_n * nz + gz;
                double ctx = arm * (ny * gz - nz * gy), cty = arm * (nz * gx - nx * gz),
                       ctz = arm * (nx * gy - ny * gx);
                tx[i] += ctx + co.mx;
                ty[i] += cty + co.my;
                tz[i] += ctz + co.mz;
                fx[i] += cfx;
                fy[i] += cfy;
                fz[i] += cfz;
                CIDX(0, n_c) = i;
                CIDX(1, n_c) = -1;
                CVAL(0, n_c) = nx;
                CVAL(1, n_c) = ny;
                CVAL(2, n_c) = nz;
                CVAL(3, n_c) = arm;
                CVAL(4, n_c) = f_n - co.f_el;
                CVAL(5, n_c) = gx;
                CVAL(6, n_c) = gy;
                CVAL(7, n_c) = gz;
                CVAL(8, n_c) = co.mdx;
                CVAL(9, n_c) = co.mdy;
                CVAL(10, n_c) = co.mdz;
                n_c++;
                w_wall += (cfx * wvx + cfy * wvy + cfz * wvz) * dt;
                if (drive_axis == 0)
                    f_drive += cfx;
                else if (drive_axis == 1)
                    f_drive += cfy;
                else
                    f_drive += cfz;
            }
        }
        CNTN(2, wl_start[n_part]);
        CNTN(3, n_c);
        CNTN(4, n_nb);
        /* particle-particle contacts (Verlet candidates) */
        for (int64_t q = 0; q < n_nb; q++) {
            int64_t i = nb_i[q];
            int64_t j = nb_j[q];
            double dx = 0.0, dy = 0.0, d2 = 0.0;
            double dz = pz[j] - pz[i];
            int touching = dz < two_r && dz > -two_r;
            if (touching) {
                dx = px[j] - px[i];
                dy = py[j] - py[i];
                d2 = dx * dx + dy * dy + dz * dz;
                touching = d2 < two_r * two_r;
            }
            double *h = hp + (i * n_part + j) * NH;
            if (!touching) {
                double lt, lr;
                release(h, kr_pp, &lt, &lr);
                d_fric += lt;
                d_roll += lr;
                continue;
            }
            double d = sqrt(d2);
            double inv_d = 1.0 / d;
            double nx = dx * inv_d, ny = dy * inv_d, nz = dz * inv_d;
            double delta = two_r - d;
            if (delta > max_overlap)
                status[c] = STATUS_OVERLAP;
            double arm = radius - 0.5 * delta;
            double hx = ox[i] + ox[j], hy = oy[i] + oy[j], hz = oz[i] + oz[j];
            contact(h, law_pp, nx, ny, nz, delta, arm,
                    vpx[i] - vpx[j], vpy[i] - vpy[j], vpz[i] - vpz[j],
                    wpx[i] + wpx[j], wpy[i] + wpy[j], wpz[i] + wpz[j],
                    dt * (vx[i] - vx[j] + arm * (hy * nz - hz * ny)),
                    dt * (vy[i] - vy[j] + arm * (hz * nx - hx * nz)),
                    dt * (vz[i] - vz[j] + arm * (hx * ny - hy * nx)),
                    dt * (ox[i] - ox[j]), dt * (oy[i] - oy[j]), dt * (oz[i] - oz[j]),
                    wpx[i] - wpx[j], wpy[i] - wpy[j], wpz[i] - wpz[j],
                    clip_attraction, stick_slip, v_reg, dt, rolling, &co);
            d_fric += co.lost_t;
            d_roll += co.lost_r;
            double f_n = co.f_n, gx = co.gx, gy = co.gy, gz = co.gz;
            double cfx = -f_n * nx + gx, cfy = -f_n * ny + gy, cfz = -f_n * nz + gz;
            double ctx = arm * (ny * gz - nz * gy), cty = arm * (nz * gx - nx * gz),
                   ctz = arm * (nx * gy - ny * gx);
            tx[i] += ctx + co.mx;
            ty[i] += cty + co.my;
            tz[i] += ctz + co.mz;
            tx[j] += ctx - co.mx;
            ty[j] += cty - co.my;
            tz[j] += ctz - co.mz;
            fx[i] += cfx;
            fy[i] += cfy;
            fz[i] += cfz;
            fx[j] -= cfx;
            fy[j] -= cfy;
            fz[j] -= cfz;
            CIDX(0, n_c) = i;
            CIDX(1, n_c) = j;
            CVAL(0, n_c) = nx;
            CVAL(1, n_c) = ny;
            CVAL(2, n_c) = nz;
            CVAL(3, n_c) = arm;
            CVAL(4, n_c) = f_n - co.f_el;
            CVAL(5, n_c) = gx;
            CVAL(6, n_c) = gy;
            CVAL(7, n_c) = gz;
            CVAL(8, n_c) = co.mdx;
            CVAL(9, n_c) = co.mdy;
            CVAL(10, n_c) = co.mdz;
            n_c++;
        }
        CNTN(5, n_c);
        /* second half kick */
        for (int64_t i = 0; i < n_part; i++) {
            vx[i] += half_dt * fx[i] * inv_m;
            vy[i] += half_dt * fy[i] * inv_m;
            vz[i] += half_dt * fz[i] * inv_m;
            ox[i] += half_dt * tx[i] * inv_i;
            oy[i] += half_dt * ty[i] * inv_i;
            oz[i] += half_dt * tz[i] * inv_i;
        }
        /* dissipation with the new full-step velocities */
        for (int64_t q = 0; q < n_c; q++) {
            int64_t i = CIDX(0, q);
            int64_t j = CIDX(1, q);
            double nx = CVAL(0, q), ny = CVAL(1, q), nz = CVAL(2, q);
            double rvx, rvy, rvz;
            if (j < 0) {
                rvx = vx[i] - wvx;
                rvy = vy[i] - wvy;
                rvz = vz[i] - wvz;
            } else {
                rvx = vx[i] - vx[j];
                rvy = vy[i] - vy[j];
                rvz = vz[i] - vz[j];
            }
            double delta_dot = rvx * nx + rvy * ny + rvz * nz;
            d_norm += CVAL(4, q) * delta_dot * dt;
            if (roll_dashpot) {
                double wx = ox[i], wy = oy[i], wz = oz[i];
                if (j >= 0) {
                    wx -= ox[j];
                    wy -= oy[j];
                    wz -= oz[j];
                }
                d_roll -= (CVAL(8, q) * wx + CVAL(9, q) * wy + CVAL(10, q) * wz) * dt;
            }
            if (stick_slip)
                continue;
            double arm = CVAL(3, q);
            double sx = ox[i], sy = oy[i], sz = oz[i];
            if (j >= 0) {
                sx += ox[j];
                sy += oy[j];
                sz += oz[j];
            }
            rvx += arm * (sy * nz - sz * ny);
            rvy += arm * (sz * nx - sx * nz);
            rvz += arm * (sx * ny - sy * nx);
            d_fric -= (CVAL(5, q) * rvx + CVAL(6, q) * rvy + CVAL(7, q) * rvz) * dt;
        }
        double *tl = A->tally + (c * A->n_cyc + cyc) * 4;
        tl[0] += w_wall;
        tl[1] += d_norm;
        tl[2] += d_fric;
        tl[3] += d_roll;
        A->samples[c * A->n_smp + smp] += f_drive;
        if (status[c] != STATUS_OK) {
            A->fail_step[c] = step0 + s + 1;
            break;
        }
    }
    for (int a = 0; a < 5; a++)
        for (int k = 0; k < 3; k++)
            memcpy(rows[a] + (k * K + c) * n_part, buf + (3 * a + k) * n_part,
                   sizeof(double) * n_part);
    memcpy(A->hist_pp + c * hp_size, hp, sizeof(double) * hp_size);
    memcpy(A->hist_pw + c * hw_size, hw, sizeof(double) * hw_size);
    free(buf);
    free(wnx);
    free(hp);
    free(c_idx);
    free(c_val);
    free(nb_i);
    free(ref_x);
#undef CIDX
#undef CVAL
}

static __attribute__((noinline)) void advance_cell_roll(int64_t c, const Args *A)
{
    advance_cell_impl(1, c, A);
}

static __attribute__((noinline)) void advance_cell_noroll(int64_t c, const Args *A)
{
    advance_cell_impl(0, c, A);
}

/* advance_cells: same argument order as the Numba function, plus the shapes */
int64_t advance_cells(double *pos, double *vel, double *omg, double *frc, double *trq,
                      const double *wall_n, const double *wall_d,
                      double radius, double mass, double inertia,
                      const double *law_pp, const double *law_pw,
                      double v_reg, int64_t clip_attraction, double gravity,
                      int64_t stick_slip, int64_t rolling, double *hist_pp, double *hist_pw,
                      double dt, int64_t step0, int64_t n_steps, double omega,
                      double accel_amp, int64_t drive_axis, int64_t steps_per_cycle,
                      int64_t sample_every, double max_overlap_fraction,
                      double *tally, double *samples, int64_t *status, int64_t *fail_step,
                      int64_t first_cell, int64_t end_cell,
                      int64_t K, int64_t N, int64_t W, int64_t n_cyc, int64_t n_smp)
{
    Args A = {pos, vel, omg, frc, trq, wall_n, wall_d, radius, mass, inertia, law_pp, law_pw,
              v_reg, clip_attraction, gravity, stick_slip, hist_pp, hist_pw, dt, step0,
              n_steps, omega, accel_amp, drive_axis, steps_per_cycle, sample_every,
              max_overlap_fraction, tally, samples, status, fail_step, K, N, W, n_cyc, n_smp};
    for (int64_t c = first_cell; c < end_cell; c++) {
        if (status[c] != STATUS_OK)
            continue;
        if (rolling)
            advance_cell_roll(c, &A);
        else
            advance_cell_noroll(c, &A);
    }
    return 0;
}
