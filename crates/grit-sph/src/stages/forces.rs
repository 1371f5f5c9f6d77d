//! The forces: the stress divergence with the normalised kernel gradient (eqs. 6 and 9), the
//! hourglass force (eq. 16), the optional artificial viscosity of the water-jet paper's solid
//! phase (its eq. 26) and gravity.

use rayon::prelude::*;

use super::pairs::{row_blocks, scatter, HalfPair, PairCache, Side, APART, NEAR_REF, USED};
use super::{
    BodyConst, KernelSums, ParTasks, SphView, StepCtx, HG_MIN_SEPARATION_H, MIN_SUPPORT_NEIGHBOURS,
};
use crate::fluid::ArtificialViscosity;
use crate::math::{Matrix, Vector};
use crate::particles::KINEMATIC;

/// One particle's acceleration and the work of its hourglass force over the step.
struct ParticleForce {
    acc: Vector,
    hourglass_work: f64,
}

/// The parts of a pair's forces that both its particles share, seen from the lower index i:
/// (σ_i/(ρ_i²Γ_i) + σ_j/(ρ_j²Γ_j)) ∇W_ij of eq. 6, which each particle scales by its partner's
/// mass, and the whole hourglass force of eq. 16 on i, which j takes with the opposite sign.
/// The gather then reads these 32 bytes per pair and nothing else.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct PairForce {
    stress: Vector,
    hourglass: Vector,
}

/// What a pair's terms of eqs. 6 and 16 read of each of its particles, in one record: the pair
/// loops reach each partner through one 152-byte record instead of eight arrays.
#[derive(Debug, Clone, Copy, Default)]
struct Partner {
    /// σ / (ρ² Γ): the factor of eq. 6 with eq. 9's normalisation.
    sig: Matrix,
    /// The velocity gradient of the kernel sums (eq. 15).
    gv: Matrix,
    def_grad: Matrix,
    x_ref: Vector,
    vel: Vector,
    rho: f64,
    /// m/ρ after the stress stage.
    vol: f64,
    mass: f64,
}

/// What the pair terms of eqs. 6 and 16 read, so that one method forms them for the scatter
/// and the gather alike, inlined into both pair loops: a closure there is compiled as a call
/// per pair that reloads every captured slice.
struct PairTerms<'a> {
    partners: &'a [Partner],
    alpha: f64,
    av: Option<&'a ArtificialViscosity>,
    h: f64,
}

impl PairTerms<'_> {
    /// The terms pair (i, j), i < j, shares between its particles (`PairForce`); c is the
    /// body's.
    #[inline(always)]
    fn of(&self, i: usize, j: usize, pair: &HalfPair, bits: u8, c: &BodyConst) -> PairForce {
        let PairTerms {
            partners,
            alpha,
            av,
            h,
        } = *self;
        if bits & APART == 0 {
            return PairForce::default();
        }
        let (a, b) = (&partners[i], &partners[j]);
        let HalfPair { xij, dw_r, .. } = *pair;
        let mut stress = (a.sig + b.sig) * (xij * dw_r);
        if let Some(av) = av {
            let (vij, rho_mean) = (a.vel - b.vel, 0.5 * (a.rho + b.rho));
            stress -= xij * (dw_r * av.pi_ab(xij, vij, c.sound, rho_mean, h));
        }
        let mut hourglass = Vector::zeros();
        if alpha > 0.0 && pair.w > 0.0 {
            let r = pair.r();
            let e = xij / r;
            // Viscous part: velocity error against the mean velocity gradient.
            let vij = a.vel - b.vel;
            let dv = (vij - (a.gv + b.gv) * xij * 0.5).dot(&e);
            let visc = 0.5 * (a.rho + b.rho) * c.sound * h * dv;
            // Stiffness part: separation error against the mean deformation gradient.
            let stiff = if bits & NEAR_REF != 0 {
                let xr = a.x_ref - b.x_ref;
                let ds = (xij - (a.def_grad + b.def_grad) * xr * 0.5).dot(&e);
                c.youngs * ds.clamp(-0.5 * r, 0.5 * r)
            } else {
                0.0
            };
            // Heavily sheared material can bring two particles almost on top of each other;
            // 1/r² then makes the pair force stiff enough to blow the explicit step up (seen
            // at 75°, impact 70). Below 0.4 h the weight stops growing; lattice neighbours
            // (r ≈ 0.77 h) are untouched.
            let rr = r.max(HG_MIN_SEPARATION_H * h);
            // Not the kernel sums' volumes: the stress stage has moved ρ since (continuity),
            // and both volumes must be the same step's.
            let cij = alpha * a.vol * b.vol * pair.w / (rr * rr);
            hourglass = e * (cij * 0.5 * (stiff + visc));
        }
        PairForce { stress, hourglass }
    }
}

/// Accelerations from the stress divergence with the normalised gradient (eq. 6, 9, with the
/// Shepard sums of `sums`), the hourglass force (eq. 16, against the velocity gradients of
/// `sums`), Monaghan's Π_ij where `Settings::solid_viscosity` asks for it, and gravity, into
/// `accel`; returns the hourglass work of the step (J/m). `vol` holds the volumes after the
/// stress stage (not the kernel sums' `sums.vol`: ρ has moved since). Each pair's shared terms
/// are evaluated once (`StepCtx::half`) into `shared`, and each particle gathers its pairs in its
/// own row's order.
pub(crate) fn forces(
    ctx: &StepCtx<'_>,
    cache: &PairCache,
    sums: &KernelSums,
    vol: &[f64],
    accel: &mut Vec<Vector>,
    shared: &mut Vec<PairForce>,
) -> f64 {
    let (s, hi, settings, dt) = (ctx.sph(), ctx.half, ctx.settings, ctx.dt);
    let (sh, gv) = (&sums.shepard, &sums.gradv);
    let SphView { p, nl, k, bc } = s;
    let alpha = settings.hourglass;
    let av = settings.solid_viscosity;
    let g = settings.gravity_m_s2;
    let h = k.h;
    let partners: Vec<Partner> = (0..p.len())
        .into_par_iter()
        .par_tasks()
        .map(|i| {
            let c = bc[p.body[i] as usize];
            let sig = if c.deformable {
                let pr = c.particle_pressure(p, i);
                (p.sdev[i] - Matrix::identity() * pr) / (p.rho[i] * p.rho[i] * sh[i])
            } else {
                Matrix::zeros()
            };
            Partner {
                sig,
                gv: gv[i],
                def_grad: p.def_grad[i],
                x_ref: p.x_ref[i],
                vel: p.vel[i],
                rho: p.rho[i],
                vol: vol[i],
                mass: p.mass[i],
            }
        })
        .collect();
    // Particles whose force is used: kinematic ones follow their prescribed motion, and
    // fragments fly ballistically.
    let moving = |i: usize| bc[p.body[i] as usize].deformable && p.flags[i] & KINEMATIC == 0;
    let is_active = |i: usize| moving(i) && cache.count[i] >= MIN_SUPPORT_NEIGHBOURS;
    // A scene of rigid bodies alone has no same-body pairs: no pass over them.
    let any_pairs = hi.start.last().is_some_and(|&s| s > 0);
    let active: Vec<bool> = if any_pairs {
        (0..p.len())
            .into_par_iter()
            .par_tasks()
            .map(is_active)
            .collect()
    } else {
        Vec::new()
    };
    let terms = PairTerms {
        partners: &partners,
        alpha,
        av: av.as_ref(),
        h,
    };
    // The particle's acceleration from its pair sums a (stress) and fhg (hourglass force).
    let finish = |i: usize, a: Vector, fhg: Vector| {
        if !is_active(i) {
            return ParticleForce {
                acc: if moving(i) { g } else { Vector::zeros() },
                hourglass_work: 0.0,
            };
        }
        ParticleForce {
            acc: a + fhg / p.mass[i] + g,
            hourglass_work: fhg.dot(&p.vel[i]) * dt,
        }
    };
    let n = p.len();
    accel.resize(n, Vector::zeros());
    if scatter() {
        // One thread: each pair's shared terms go straight to both particles, in id order.
        // Particle i gets them from its lower partners' rows, in increasing index, before its
        // own row's: its row's order, so every sum is bitwise the gather's below.
        let mut a = vec![Vector::zeros(); n];
        let mut fhg = vec![Vector::zeros(); n];
        if any_pairs {
            for i in 0..n {
                let at = hi.start[i] as usize;
                let pairs = cache.half[at..].iter().zip(&cache.flags[at..]);
                let c = bc[p.body[i] as usize];
                for (&j, (pair, &bits)) in hi.upper_of(nl, i).iter().zip(pairs) {
                    let j = j as usize;
                    if bits & USED == 0 || !(active[i] || active[j]) {
                        continue;
                    }
                    let f = terms.of(i, j, pair, bits, &c);
                    if active[i] {
                        a[i] += f.stress * partners[j].mass;
                        fhg[i] -= f.hourglass;
                    }
                    if active[j] {
                        a[j] += -f.stress * partners[i].mass;
                        fhg[j] -= -f.hourglass;
                    }
                }
            }
        }
        let mut work = 0.0;
        for (i, acc) in accel.iter_mut().enumerate() {
            let f = finish(i, a[i], fhg[i]);
            *acc = f.acc;
            work += f.hourglass_work;
        }
        return work;
    }
    let blocks = if any_pairs {
        row_blocks(shared, &hi.start)
    } else {
        Vec::new()
    };
    blocks
        .into_par_iter()
        .flat_map_iter(|rows| rows.rows())
        .for_each(|(i, row)| {
            let js = hi.upper_of(nl, i);
            let at = hi.start[i] as usize;
            let pairs = cache.half[at..].iter().zip(&cache.flags[at..]);
            let c = bc[p.body[i] as usize];
            for ((out, &j), (pair, &bits)) in row.iter_mut().zip(js).zip(pairs) {
                let j = j as usize;
                if bits & USED == 0 || !(active[i] || active[j]) {
                    continue;
                }
                *out = terms.of(i, j, pair, bits, &c);
            }
        });
    let shared = &*shared;
    let gather = |i: usize| {
        if !is_active(i) {
            return finish(i, Vector::zeros(), Vector::zeros());
        }
        let mut a = Vector::zeros();
        let mut fhg = Vector::zeros();
        for &Side { j, id } in cache.of(nl, i) {
            let f = shared[id as usize];
            let (stress, hourglass) = if (j as usize) < i {
                (-f.stress, -f.hourglass)
            } else {
                (f.stress, f.hourglass)
            };
            a += stress * p.mass[j as usize];
            fhg -= hourglass;
        }
        finish(i, a, fhg)
    };
    // Written in place; the work is then summed in particle order, whatever the threads.
    let mut work = vec![0.0; n];
    accel
        .par_iter_mut()
        .zip(work.par_iter_mut())
        .par_tasks()
        .enumerate()
        .for_each(|(i, (acc, w))| {
            let f = gather(i);
            (*acc, *w) = (f.acc, f.hourglass_work);
        });
    work.iter().fold(0.0, |hg, w| hg + w)
}
