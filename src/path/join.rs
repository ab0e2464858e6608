//! Joining at a transition point: the classes that fit a point, the neighbouring pieces
//! that contain it and enter their own region, the directional problem at a zero-force
//! vertex, folds, bifurcations and the choice of a branch.

use super::advance::GuardRow;
use super::*;
use crate::dense::max_abs_diff;

/// The widest of `transit`'s last-resort thresholds, as a multiple of the usual ones.
pub(super) const MAX_WIDENING: f64 = 64.0;

/// The usual thresholds [`MAX_WIDENING`] times wider, an open node's λt against 1 + F times
/// them ([`Widen::cone`]): what any of `transit`'s retries could let a node fit.
const WIDEST: Widen = Widen {
    k: MAX_WIDENING,
    cone: true,
    ..Widen::USUAL
};

/// The pieces before the current one that `transit` compares a candidate with (a way back
/// along one of them, across pieces a rounding long, is not a branch).
const RETRACE_LOOKBACK: usize = 4;

/// A bound on how far the data determine q, relative to the load's terms
/// ([`Path::undetermined_fit`]): the condensation's relative error, about κ(A) ε, is below
/// it wherever A is well enough conditioned for double.
const DETERMINATION_BOUND: f64 = 1e-8;

/// How near a transition point under an affine load may be to a point where every
/// contact force vanishes for [`Path::snap_to_vertex`] to move it there: its forces at most
/// this fraction of the force scale along the piece, and its α at most this fraction of
/// the piece's length in α from that point's. (A body pressed flat on the foundation with
/// zero gaps, unloaded by `α f1` from α = 1: the last piece's first force root came 9.6e-9
/// from α = 0, the error of the piece's tangent times its length, the forces there 1e-8 of
/// the entry's; 5 of 28 such strips with p = 125 to 390 stopped with "fits no class".)
const NEAR_VANISHING: f64 = 1e-6;

/// Newton iterations of a directional problem from the point's last directional solution
/// (see [`Path::directional_classes`]) before it is solved from zero forces.
const NEAR_NEWTON_ITERATIONS: usize = 20;

/// How far from zero (times its threshold) a node's normal force must be for a change
/// between its slip classes to be an unresolved stick phase ([`Path::unresolved_cone`]).
/// Both slip classes fit only where `2 F |λν|` is within the force threshold (at most
/// [`MAX_WIDENING`] times the usual one), so at this factor only nodes with F below about
/// 0.06 can trip it; a node whose normal force is nearer zero passes between slip classes
/// through a point where every force of it is at zero.
const UNRESOLVED_CONE: f64 = 1e3;

#[cfg(test)]
thread_local! {
    /// Test switch: every directional solve of the enumeration's first pass fails, as
    /// where only the solver's last stages solve the directional problem; the count of
    /// solves it refused (see `tests::the_second_pass_finds_what_the_first_misses`).
    static FIRST_PASS_REFUSES: std::cell::Cell<Option<usize>> =
        const { std::cell::Cell::new(None) };
}

/// A directional solution of the current point (see `Path::directional_warm`).
pub(super) struct DirectionalWarm {
    /// The way along α (±1).
    s: f64,
    /// The point's `q'`.
    dq: Vec<f64>,
    /// The solution `λ̇`.
    lam: Vec<f64>,
    /// The factorisation of its piece, where the solver kept one.
    lu: Option<UpdatedLu>,
}

impl Path {
    /// No displacement row's threshold below twice how far the data determine q's rows
    /// ([`crate::load::BoundLoad::determination`], in force units), nor that floor above
    /// a few times the relative error of the condensation
    /// ([`crate::load::BoundLoad::relative_determination`]) times the terms of the row's
    /// node ([`Widen::determined`]). None where that is not known (a host's solve,
    /// condensed input, a general load not evaluated at `pt` last).
    fn determined(&self, pt: &Point) -> Option<Widen> {
        let del = self.problem.delassus();
        let det = self.load.determination(pt.alpha, del)?;
        Some(Widen {
            min_row: 2.0 * self.problem.default_r() * det,
            determined: self.load.relative_determination(pt.alpha, del)?,
            ..Widen::USUAL
        })
    }

    /// `transit`'s last-resort thresholds at `pt`, as arguments of [`Tol::widened`]: first
    /// the usual ones with [`Widen::cone`] (the forces' own rounding: an open node's λt
    /// against 1 + F times its threshold, nothing else wider); then
    /// [`Self::determined`]; then, in double, all of them 4, 16 and 64 times wider, as far
    /// as κ(W) times the relative error of the condensation
    /// ([`crate::load::BoundLoad::relative_determination`], about κ(A) ε) exceeds
    /// `zero_tol` (the forces are undetermined by that much); last, the determined ones
    /// with [`Widen::cone`]. (The cone's alone where the determination is not known.)
    ///
    /// The cone's come before the data's determination, which widens the displacement
    /// rows by orders of magnitude: on slender strips in double (`fe_strip` seeds 6 and
    /// 1597, κ(W) 1.8e8 and 1.0e8, F = 5 and 1) a slipping node's λν reached 0 with its
    /// λt above its usual threshold by rounding, so no class fitted it; at the data's
    /// determination its tangential displacement (7.8e-8 and 6.7e-8 in force units, about 1e6
    /// times its usual threshold) counted as zero, and stick (reversing α, a fold the
    /// path does not have) or slip the other way was taken where the independent
    /// reference lifts off. Each path then stopped with a node fitting no class.
    fn widening(&self, pt: &Point) -> Vec<Widen> {
        let cone = Widen {
            cone: true,
            ..Widen::USUAL
        };
        let Some(first) = self.determined(pt) else {
            return vec![cone];
        };
        let mut out = vec![cone, first];
        if !self.problem.extended_precision() {
            // `first.determined` is the condensation's relative error
            let bound = self.problem.w_condition_estimate() * first.determined / self.opts.zero_tol;
            let mut k = 4.0;
            while k <= bound.min(MAX_WIDENING) {
                out.push(Widen { k, ..first });
                k *= 4.0;
            }
        }
        out.push(Widen {
            cone: true,
            ..first
        });
        out
    }

    /// [`Self::determined`] at `pt` where it changes the classes some node of `nodes` fits
    /// (else None). How far the data determine q costs a few solves with A (once per
    /// path), so it is found only where a bound on it changes them: no displacement row's
    /// threshold below [`DETERMINATION_BOUND`] of the load's terms (nor that above a few
    /// times it of its node's terms).
    fn undetermined_fit(&self, pt: &Point, nodes: &[usize]) -> Option<Widen> {
        let tol = self.tol_at(pt);
        let usual = self.compatible(nodes, pt, &tol);
        let bound = Widen {
            min_row: 2.0
                * self.problem.default_r()
                * DETERMINATION_BOUND
                * inf_norm(&self.term_rows(pt).0),
            determined: DETERMINATION_BOUND,
            ..Widen::USUAL
        };
        if self.compatible(nodes, pt, &tol.clone().widened(bound)) == usual {
            return None;
        }
        let widen = self.determined(pt)?;
        (self.compatible(nodes, pt, &tol.widened(widen)) != usual).then_some(widen)
    }

    /// The continuations at the widened thresholds `widen` (`continuations_either`) less
    /// the way back (`retraces`); in extended precision also less those that do not pass
    /// through the point to those thresholds (see `transit_at`'s last resort).
    #[allow(clippy::too_many_arguments)]
    fn widened_continuations(
        &mut self,
        pt: &Point,
        fixed: &[Class],
        nodes: &[usize],
        back: Option<(&[Class], &[f64])>,
        blockers: &mut Vec<usize>,
        widen: Widen,
        retraces: &dyn Fn(&Candidate) -> bool,
    ) -> Result<Vec<Candidate>> {
        let mut wider = self.continuations_either(pt, fixed, nodes, back, blockers, widen)?;
        wider.retain(|cd| !retraces(cd));
        if self.problem.extended_precision() {
            let tol = self.tol_at(pt).widened(widen);
            wider.retain(|cd| self.passes_through_at(pt, cd, &tol));
        }
        Ok(wider)
    }

    /// Whether a guard of a node of `nodes` on candidate `cd` reaches zero within a
    /// rounding of `pt` ([`ROUNDING_LONG`] in α and in the forces): the node would switch
    /// again at once, so the candidate may be an artefact of the point's rounding.
    fn rounding_short(&self, pt: &Point, cd: &Candidate, nodes: &[usize]) -> bool {
        let m = cd.t.len() - 1;
        let step = self
            .guard_table(&cd.classes, pt, Some((&cd.t, &cd.rate)))
            .into_iter()
            .filter(|row| nodes.contains(&row.guard.node) && row.value > 0.0 && row.slope < 0.0)
            .map(|row| row.value / -row.slope)
            .fold(f64::INFINITY, f64::min);
        step * cd.t[m].abs() <= ROUNDING_LONG * pt.alpha.abs().max(1.0)
            && step * inf_norm(&cd.t[..m]) <= ROUNDING_LONG * self.force_scale(pt)
    }

    /// Classes of each node in `nodes` whose equations and guards hold at the point (to
    /// `tol`, in force units). One product with W for all of them.
    pub(super) fn compatible(&self, nodes: &[usize], pt: &Point, tol: &Tol) -> Vec<Vec<Class>> {
        let d = self.gaps(pt);
        nodes
            .iter()
            .map(|&i| self.compatible_at(i, &pt.lam, &d, tol))
            .collect()
    }

    /// Classes of node `i` compatible with `(λ, d)` (to `tol`, in force units).
    pub(super) fn compatible_at(&self, i: usize, lam: &[f64], d: &[f64], tol: &Tol) -> Vec<Class> {
        let c = self.consts();
        let r0 = c.r0;
        Class::ALL
            .into_iter()
            .filter(|&cl| {
                let eq_ok = c.equations(i, cl).iter().enumerate().all(|(k, e)| {
                    // equations in force units: displacement rows scaled by r0 instead of r
                    let [a0, a1] = e.lam;
                    let v = a0.coef * lam[a0.index]
                        + a1.coef * lam[a1.index]
                        + if e.disp.coef != 0.0 {
                            e.disp.coef.signum() * r0 * d[e.disp.index]
                        } else {
                            0.0
                        };
                    v.abs()
                        <= tol.of(e) * tol.cone_factor(cl == Class::Open && k == 1, c.friction[i])
                });
                eq_ok
                    && crate::piece::guard_kinds(cl).iter().all(|&kind| {
                        let g = Guard { node: i, kind };
                        let f = c.guard_form(g);
                        let t = if c.label_only(g) {
                            tol.label_of(&f)
                        } else {
                            tol.of(&f)
                        };
                        f.eval(lam, d) >= -t
                    })
            })
            .collect()
    }

    /// Whether guard `row` (its slope taken along a piece's tangent t) lets the way `s`
    /// along t (±1) into the piece's region at the point: None when it does; Some(true)
    /// when it is at zero (see [`Tol::at_zero`]; `tol_switching` for the nodes of
    /// `switching`, whose guards are zero by construction, see [`Self::push_candidates`])
    /// and does not increase (`relaxed`: decreases beyond its slope threshold);
    /// Some(false) when it is below zero (the piece does not contain the point).
    fn guard_blocks(
        &self,
        row: &GuardRow,
        s: f64,
        (tol, tol_switching): (&Tol, &Tol),
        switching: &[usize],
        relaxed: bool,
    ) -> Option<bool> {
        let (v, vd) = (row.value, s * row.slope);
        // A guard not at zero must be inside; one at zero must increase: its slope (force
        // per unit of scaled arclength) against the scale of the point.
        let form = self.consts().guard_form(row.guard);
        // (positive, its root a distinct step away in double-double: see `transit`)
        if v > 0.0 && self.resolved.borrow().contains(&row.guard) {
            return None;
        }
        let tol_row = if switching.contains(&row.guard.node) {
            tol_switching
        } else {
            tol
        };
        let at_zero = if self.consts().label_only(row.guard) {
            tol_row.at_zero_label(&form, v, vd)
        } else {
            tol_row.at_zero(&form, v, vd)
        };
        if !at_zero {
            return if v > 0.0 { None } else { Some(false) };
        }
        let ts = tol.slope();
        let ok = if relaxed { vd >= -ts } else { vd > ts };
        (!ok).then_some(true)
    }

    /// Adds the directions of piece `classes` through `pt` that enter its region.
    /// `switching`: the nodes that change class at the point. Their guards on the new
    /// piece are the old class's equations or guards, so one near zero is zero by
    /// construction: it is compared with the whole threshold of its terms (as at a start),
    /// not with its rounding, and the way along the piece is decided by its slope (on a
    /// slender strip the new slip guard of a node leaving stick came out at −2.4e-15, a
    /// tenth of its threshold, with slope +1.1e-9, and no piece continued the path).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn push_candidates(
        &self,
        classes: &[Class],
        pt: &Point,
        scale: f64,
        tol: &Tol,
        switching: &[usize],
        back: Option<(&[Class], &[f64])>,
        relaxed: bool,
        out: &mut Vec<Candidate>,
        blockers: &mut Vec<usize>,
    ) {
        // A frictionless node (F = 0) in contact slips: stick's region (F λν < λt < −F λν)
        // is empty, and S+ and S− have the same equations (dν = 0, λt = 0), so the sign
        // of its dt, not an enumeration, tells them apart (see `flips` below).
        let consts = self.consts();
        let normalised: Vec<Class> = classes
            .iter()
            .enumerate()
            .map(|(i, &cl)| {
                if cl == Class::Stick && consts.frictionless(i) {
                    Class::SlipPlus
                } else {
                    cl
                }
            })
            .collect();
        let classes = &normalised[..];
        let can_flip = classes.iter().enumerate().any(|(i, &cl)| {
            matches!(cl, Class::SlipPlus | Class::SlipMinus) && consts.frictionless(i)
        });
        // The piece the path came from cannot continue it: its crossing guard decreases
        // forward, and backward is where the path came from.
        if !can_flip && back.is_some_and(|(bc, _)| bc == classes) {
            return;
        }
        let tol_switching = tol.clone().approximate();
        let Some(PieceTangent {
            t,
            lu,
            scales,
            orientation: lu_orientation,
            rate,
            xp,
        }) = self.tangent(classes, pt, scale)
        else {
            return;
        };
        let lu = Arc::new(lu);
        // One table along t; along −t the slopes change sign.
        let table = self.guard_table(classes, pt, Some((&t, &rate)));
        let rate = Arc::new(rate);
        let xp = xp.map(Arc::new);
        for s in [1.0, -1.0] {
            let ts: Vec<f64> = t.iter().map(|v| s * v).collect();
            let blocks = |row: &GuardRow| -> Option<bool> {
                self.guard_blocks(row, s, (tol, &tol_switching), switching, relaxed)
            };
            // A frictionless node whose dt is at zero and decreases beyond its slope
            // threshold along this way slips the other way: the same piece, the other sign.
            // (Its S+ and S− entered a point where dt stays at zero, as on a symmetric
            // body's axis, as two continuations, a bifurcation that was none; and tens of
            // such nodes at once, where the tangential load turns, were 3^k pieces.)
            let flips: Vec<bool> = table
                .iter()
                .map(|row| {
                    consts.label_only(row.guard)
                        && blocks(row) == Some(true)
                        && s * row.slope < -tol.slope()
                })
                .collect();
            let mut classes_s = classes.to_vec();
            for (row, _) in table.iter().zip(&flips).filter(|(_, f)| **f) {
                let cl = &mut classes_s[row.guard.node];
                *cl = if *cl == Class::SlipPlus {
                    Class::SlipMinus
                } else {
                    Class::SlipPlus
                };
            }
            if back.is_some_and(|(bc, _)| bc == classes_s)
                || out.iter().any(|c| {
                    c.classes == classes_s
                        && c.t.iter().zip(&ts).map(|(a, b)| a * b).sum::<f64>() > 0.0
                })
            {
                continue;
            }
            let enters = table
                .iter()
                .zip(&flips)
                .all(|(row, &flip)| flip || blocks(row).is_none());
            if !enters {
                // Nodes not switching whose guard is at zero and leaves: see `transit`.
                blockers.extend(
                    table
                        .iter()
                        .filter(|row| {
                            !switching.contains(&row.guard.node) && blocks(row) == Some(true)
                        })
                        .map(|row| row.guard.node),
                );
            }
            if enters {
                out.push(Candidate::along(
                    &classes_s,
                    s,
                    (&lu, lu_orientation, scales),
                    (&t, &rate),
                    xp.clone(),
                ));
            }
        }
    }

    /// Every neighbouring piece that contains `pt` and whose direction enters its region.
    /// `fixed` gives the class of every node not in `nodes`; the nodes in `nodes` take all
    /// their compatible classes. `back` = (classes, tangent) of the way the path came.
    ///
    /// Nodes at the *vertex* (`λ_i = 0`, `d_i = 0`: every class fits) are not enumerated
    /// when there are more than two of them: the continuation from such a point is
    /// positively homogeneous, so their classes are read off the solution of the
    /// directional contact problem `ḋ = W λ̇ ± q'` (the other nodes keep their class).
    /// Where the other nodes have more than [`MAX_DIRECTIONAL_COMBINATIONS`] combinations
    /// of classes and each fits two, theirs come from [`Self::pivoted_classes`] (and from
    /// the enumeration, up to [`MAX_CANDIDATE_PIECES`], where that finds none).
    #[allow(clippy::too_many_arguments)]
    fn continuations(
        &self,
        pt: &Point,
        fixed: &[Class],
        nodes: &[usize],
        back: Option<(&[Class], &[f64])>,
        relaxed: bool,
        blockers: &mut Vec<usize>,
        widen: Widen,
    ) -> Result<Vec<Candidate>> {
        let scale = self.force_scale(pt);
        // A start (no way in) is a point of the fixed-α solver, known to its accuracy.
        let tol = match back {
            Some(_) => self.tol_at(pt),
            None => self.tol_at(pt).approximate(),
        }
        .widened(widen);
        let options: Vec<Vec<Class>> = self.compatible(nodes, pt, &tol);
        if let Some(k) = options.iter().position(|o| o.is_empty()) {
            return Err(Error::Numerical(format!(
                "node {} fits no class at alpha = {:e} (the point is not a solution){}",
                nodes[k] + 1,
                pt.alpha,
                near_overflow(pt)
            )));
        }
        let is_vertex: Vec<bool> = options.iter().map(|o| o.len() == 4).collect();
        // A frictionless node in contact is enumerated as one slip class, its sign read off
        // its dt by `push_candidates` (the class it had where it fits, else S+).
        let consts = self.consts();
        let options: Vec<Vec<Class>> = options
            .into_iter()
            .zip(nodes)
            .map(|(o, &i)| {
                let slips = [Class::SlipPlus, Class::SlipMinus];
                if !consts.frictionless(i) || !o.iter().any(|c| slips.contains(c)) {
                    return o;
                }
                let keep = if o.contains(&fixed[i]) && slips.contains(&fixed[i]) {
                    fixed[i]
                } else if o.contains(&Class::SlipPlus) {
                    Class::SlipPlus
                } else {
                    Class::SlipMinus
                };
                o.into_iter()
                    .filter(|&c| c == Class::Open || c == keep)
                    .collect()
            })
            .collect();
        // Every neighbouring piece is examined while they are few enough (this finds every
        // directional solution at a zero-force vertex, hence every branch); beyond that,
        // the nodes at the vertex take their classes from the directional problem (one
        // solution per way along α).
        let use_directional = options
            .iter()
            .fold(1usize, |acc, o| acc.saturating_mul(o.len()))
            > MAX_CANDIDATE_PIECES;
        let enumerated: Vec<usize> = (0..nodes.len())
            .filter(|&k| !(use_directional && is_vertex[k]))
            .collect();
        let combos = enumerated
            .iter()
            .fold(1usize, |acc, &k| acc.saturating_mul(options[k].len()));
        let limit = if use_directional {
            MAX_DIRECTIONAL_COMBINATIONS
        } else {
            MAX_CANDIDATE_PIECES
        };
        // Many nodes at a boundary between two classes at once (identical nodes reaching
        // their friction limit together): a continuation per way along α by pivoting on
        // their classes (those at the vertex from the directional problem).
        let pivoting = enumerated.iter().all(|&k| options[k].len() <= 2);
        if combos > limit && pivoting {
            let mut out = Vec::new();
            // First with the directional problem's stalled solves taken where close (see
            // `DIRECTIONAL_LOOSE`), then, where that took one and found nothing, without.
            for loose in [true, false] {
                let took = Cell::new(false);
                for want in [1.0, -1.0] {
                    let Some(cl) = self.pivoted_classes(
                        pt,
                        fixed,
                        (nodes, &options, &is_vertex),
                        (want, relaxed),
                        &tol,
                        loose.then_some(&took),
                    ) else {
                        continue;
                    };
                    self.push_candidates(
                        &cl, pt, scale, &tol, nodes, back, relaxed, &mut out, blockers,
                    );
                }
                if !out.is_empty() || !took.get() {
                    break;
                }
            }
            // (none: the relaxed slopes of `continuations_either` may find one; or the
            // enumeration below, where the combinations are few enough for it)
            if !out.is_empty() || (!relaxed && combos > MAX_CANDIDATE_PIECES) {
                return Ok(out);
            }
        }
        if combos > MAX_CANDIDATE_PIECES {
            return Err(Error::Numerical(format!(
                "{} nodes are at a class boundary at once at alpha = {:e}: {combos} neighbouring pieces exceed the limit of {MAX_CANDIDATE_PIECES}{}",
                enumerated.len(),
                pt.alpha,
                if pivoting {
                    ", and pivoting on their classes found no continuation"
                } else {
                    ""
                }
            )));
        }
        // With the vertex nodes from the directional problem, each combination's solves
        // are first cut short after their first stages (`solve::Stages::First`); all
        // stages run only where that pass finds no continuation and cut a solve short.
        // (In double on the strip of `MAX_DIRECTIONAL_COMBINATIONS`, solves that failed
        // after every stage, about 1 s each, were 61 s of 100.)
        // (the nodes whose classes the directional problem gives, by node)
        let mut free = vec![false; fixed.len()];
        for (k, &i) in nodes.iter().enumerate() {
            free[i] = use_directional && is_vertex[k];
        }
        for quick in [use_directional, false] {
            let mut out = Vec::new();
            let mut cut = false;
            let mut idx = vec![0usize; enumerated.len()];
            'combinations: loop {
                let mut classes = fixed.to_vec();
                for (k, &e) in enumerated.iter().enumerate() {
                    classes[nodes[e]] = options[e][idx[k]];
                }
                if use_directional {
                    let frozen: Vec<Option<Class>> = classes
                        .iter()
                        .zip(&free)
                        .map(|(&c, &f)| (!f).then_some(c))
                        .collect();
                    for s in [1.0, -1.0] {
                        match self.directional_classes(pt, &frozen, s, quick, None) {
                            Ok(cl) => self.push_candidates(
                                &cl, pt, scale, &tol, nodes, back, relaxed, &mut out, blockers,
                            ),
                            Err(short) => cut |= short,
                        }
                    }
                } else {
                    self.push_candidates(
                        &classes, pt, scale, &tol, nodes, back, relaxed, &mut out, blockers,
                    );
                }
                // next combination
                let mut k = 0;
                loop {
                    if k == enumerated.len() {
                        break 'combinations;
                    }
                    idx[k] += 1;
                    if idx[k] < options[enumerated[k]].len() {
                        break;
                    }
                    idx[k] = 0;
                    k += 1;
                }
            }
            if !out.is_empty() || !cut {
                return Ok(out);
            }
        }
        // (the pass with every stage cuts nothing short and returns above)
        Ok(Vec::new())
    }

    /// The classes of the piece that continues the path from `pt` with α moving along
    /// `want` (±1), where more nodes are at a boundary between two classes than
    /// [`Self::continuations`] enumerates ([`MAX_CANDIDATE_PIECES`] pieces, or
    /// [`MAX_DIRECTIONAL_COMBINATIONS`] beside nodes at a vertex): `nodes` fit the
    /// classes `options` (one or two each, or all four at a zero-force vertex, `vertex`:
    /// those take theirs from [`Self::directional_classes`] with the others' classes at
    /// each step), every other node keeps its class in `fixed`.
    /// Which of the two classes a node takes is a linear complementarity problem in the
    /// rates (the directional problem of the point, as at a zero-force vertex): a node
    /// whose guard at zero decreases along the piece's tangent must take its other class.
    /// Solved by principal pivoting, each step one piece's tangent (O(m²) by updates):
    /// every node so blocked switches at once while that lowers their number, else the
    /// first blocked node alone (Murty's rule, finite where the rates' matrix is a
    /// P-matrix). None when a node outside `nodes` blocks, a class vector comes back, the
    /// tangent does not move α, or after `4·|nodes| + 64` steps. What it returns is only a
    /// candidate: [`Self::push_candidates`] checks that its piece enters its region. One
    /// continuation per way: several (a bifurcation among these nodes) are not searched.
    fn pivoted_classes(
        &self,
        pt: &Point,
        fixed: &[Class],
        (nodes, options, vertex): (&[usize], &[Vec<Class>], &[bool]),
        (want, relaxed): (f64, bool),
        tol: &Tol,
        loose: Option<&Cell<bool>>,
    ) -> Option<Vec<Class>> {
        let scale = self.force_scale(pt);
        let tol_switching = tol.clone().approximate();
        let mut classes = fixed.to_vec();
        let mut slots = vec![None; classes.len()];
        for (k, &i) in nodes.iter().enumerate() {
            if !options[k].contains(&classes[i]) {
                classes[i] = options[k][0];
            }
            slots[i] = Some(k);
        }
        let any_vertex = vertex.iter().any(|&v| v);
        let mut seen = std::collections::HashSet::new();
        let (mut fewest, mut single) = (usize::MAX, false);
        for _ in 0..4 * nodes.len() + 64 {
            if any_vertex {
                let frozen: Vec<Option<Class>> = classes
                    .iter()
                    .enumerate()
                    .map(|(i, &c)| (!slots[i].is_some_and(|k| vertex[k])).then_some(c))
                    .collect();
                classes = self
                    .directional_classes(pt, &frozen, want, false, loose)
                    .ok()?;
            }
            if !seen.insert(classes.clone()) {
                return None;
            }
            let tangent = self.tangent(&classes, pt, scale)?;
            let t_alpha = tangent.t.last().copied().unwrap_or(0.0);
            if t_alpha == 0.0 || !t_alpha.is_finite() {
                return None;
            }
            let s = want * t_alpha.signum();
            let table = self.guard_table(&classes, pt, Some((&tangent.t, &tangent.rate)));
            let mut blocked = Vec::new();
            for row in &table {
                match self.guard_blocks(row, s, (tol, &tol_switching), nodes, relaxed) {
                    None => {}
                    Some(true) => match slots[row.guard.node] {
                        Some(k) if options[k].len() == 2 => blocked.push(k),
                        _ => return None,
                    },
                    Some(false) => return None,
                }
            }
            blocked.sort_unstable();
            blocked.dedup();
            if blocked.is_empty() {
                return Some(classes);
            }
            single |= blocked.len() >= fewest;
            fewest = fewest.min(blocked.len());
            let flip = if single { &blocked[..1] } else { &blocked[..] };
            for &k in flip {
                let i = nodes[k];
                classes[i] = if classes[i] == options[k][0] {
                    options[k][1]
                } else {
                    options[k][0]
                };
            }
        }
        None
    }

    /// [`Self::continuations`] with the slopes of guards at zero strictly positive, else,
    /// where that finds none, with slopes within their threshold of zero.
    pub(super) fn continuations_either(
        &self,
        pt: &Point,
        fixed: &[Class],
        nodes: &[usize],
        back: Option<(&[Class], &[f64])>,
        blockers: &mut Vec<usize>,
        widen: Widen,
    ) -> Result<Vec<Candidate>> {
        let cands = self.continuations(pt, fixed, nodes, back, false, blockers, widen)?;
        if !cands.is_empty() {
            return Ok(cands);
        }
        self.continuations(pt, fixed, nodes, back, true, blockers, widen)
    }

    /// Classes of the free (vertex) nodes on the continuation with `α̇ = s`: the solution of
    /// the contact problem for the derivatives, `ḋ = W λ̇ + s q'`, with the frozen nodes'
    /// equations. `Err(false)` where the solver finds no solution or a free node stays
    /// degenerate; with `quick`, `Err(true)` where the solver's first stages find none
    /// (`solve::Stages::First`: the last ones may). With `loose`, a stalled iterate of the
    /// solver within [`DIRECTIONAL_LOOSE`] is taken as the solution, and `loose` is set
    /// when one was (the caller checks the classes on their piece, and solves again
    /// without where that finds no continuation).
    pub(super) fn directional_classes(
        &self,
        pt: &Point,
        frozen: &[Option<Class>],
        s: f64,
        quick: bool,
        loose: Option<&Cell<bool>>,
    ) -> std::result::Result<Vec<Class>, bool> {
        #[cfg(test)]
        if let Some(n) = FIRST_PASS_REFUSES.get().filter(|_| quick) {
            FIRST_PASS_REFUSES.set(Some(n + 1));
            return Err(true);
        }
        let qdir: Vec<f64> = pt.dq.iter().map(|v| s * v).collect();
        // From the last solution of this point's problem along this way (for other
        // classes of the frozen nodes, which most combinations and pivoting steps change
        // for a few nodes only), by Newton alone: on a slender strip in double (458 × 3,
        // F = 5, κ(W) 5e9) about 140 nodes were at the vertex at once within the widened
        // thresholds, and each of the 64 solves of a point from zero forces took about 9
        // fresh factorisations (Newton stalled; the active-set iteration solved it).
        // Where that does not converge, from zero forces and the path's factorisation,
        // as ever.
        let near = {
            let warm = self.directional_warm.borrow();
            warm.iter()
                .find(|w| w.s == s && w.dq == pt.dq)
                .map(|w| (w.lam.clone(), w.lu.clone()))
        };
        let (lam, lu) = match near.and_then(|(lam, lu)| {
            newton_near(
                &self.problem,
                &qdir,
                lam,
                Some(frozen),
                lu,
                NEAR_NEWTON_ITERATIONS,
            )
        }) {
            Some(solved) => solved,
            None => {
                let mut take = |lam: &[f64]| -> Option<Vec<f64>> {
                    let cell = loose?;
                    let r = crate::solve::residual_of(&self.problem, &qdir, lam, Some(frozen));
                    (r <= DIRECTIONAL_LOOSE).then(|| {
                        cell.set(true);
                        lam.to_vec()
                    })
                };
                solve_with_frozen(
                    &self.problem,
                    &qdir,
                    None,
                    pt.alpha,
                    Some(frozen),
                    if quick { Stages::First } else { Stages::All },
                    self.updater.borrow().clone(),
                    loose
                        .is_some()
                        .then_some(&mut take as &mut dyn FnMut(&[f64]) -> _),
                )
                .map_err(|_| quick)?
            }
        };
        {
            let mut warm = self.directional_warm.borrow_mut();
            warm.retain(|w| !(w.s == s && w.dq == pt.dq));
            warm.push(DirectionalWarm {
                s,
                dq: pt.dq.clone(),
                lam: lam.clone(),
                lu,
            });
        }
        let w = self.problem.delassus().w();
        let d = displacement_gaps(w, &qdir, &lam);
        let r0 = self.problem.default_r();
        let sc = inf_norm(&lam).max(r0 * inf_norm(&qdir)).max(1e-300);
        let tol = Tol::uniform(self.opts.zero_tol * sc);
        let mut classes = Vec::with_capacity(frozen.len());
        for (i, f) in frozen.iter().enumerate() {
            match f {
                Some(c) => classes.push(*c),
                None => {
                    let comp = self.compatible_at(i, &lam, &d, &tol);
                    if comp.len() != 1 {
                        return Err(false);
                    }
                    classes.push(comp[0]);
                }
            }
        }
        Ok(classes)
    }

    /// Handles a transition point: finds the neighbouring pieces that continue the path,
    /// records the events and moves onto the chosen piece.
    pub(super) fn transit(
        &mut self,
        cur: CurrentPiece,
        pt: Point,
        crossing: Vec<Guard>,
    ) -> Result<StepOutcome> {
        let out = self.transit_at(cur, pt, crossing);
        self.resolved.borrow_mut().clear();
        self.directional_warm.borrow_mut().clear();
        out
    }

    /// [`Self::transit`], which clears the point's resolved guards and directional
    /// solutions after it.
    fn transit_at(
        &mut self,
        cur: CurrentPiece,
        pt: Point,
        crossing: Vec<Guard>,
    ) -> Result<StepOutcome> {
        let tol = self.tol_at(&pt);
        let c = self.consts();
        let mut nodes: Vec<usize> = crossing.iter().map(|g| g.node).collect();
        // Guards at zero (Tol::at_zero, with their slopes along the way the path came):
        // the nodes switching at this point together with the crossing one.
        let mut by_value = Vec::new();
        let mut resolved = Vec::new();
        for GuardRow {
            guard: g,
            value: v,
            slope: vd,
        } in self.guard_table(&cur.classes, &pt, Some((&cur.t, &cur.rate)))
        {
            let form = c.guard_form(g);
            if v <= 0.0 || tol.at_zero(&form, v, vd) {
                if v > 0.0 && v > tol.arc * vd.abs() {
                    by_value.push((g, form));
                } else {
                    nodes.push(g.node);
                }
            }
        }
        // A positive guard that is at zero by its value only (within its rounding in
        // double, not crossing within zero_tol along the tangent): where the piece is
        // carried in double-double (an affine or basis load in extended precision), its
        // own root on the refined line (a basis load's: one Newton step on its refined
        // solutions) decides. One more than RESOLVED_APART of α's unit away, ahead (its
        // own transition, later) or behind (its node switched a step before), the guard is
        // positive here: its node does not switch, and the candidate pieces take the
        // guard as inside (`resolved`, see `push_candidates`). On a slender strip
        // (801 × 5 on 103 × 0.245, F = 3, κ(W) 5e10) the gap of the next node of a
        // closing front was 6.2e-14 (1.4e-14 of its terms, a hundredth of its threshold)
        // where a node at the free end touched down, its root 1e-5 later in α: it touched
        // down there with it, 30 times over, each 1e-5 to 4e-5 early (the reference tracer
        // has every touchdown on its own), until a node fit no class. On a 401 × 5 strip
        // (F = 5) three events, 3e-5 in α apart in the reference, were one; and a node
        // that had opened 1.9e-5 before in α, its gap still increasing, closed again where
        // its neighbour opened, 4.2e-6 before its own root (the reference's).
        if !by_value.is_empty() {
            let forms: Vec<crate::piece::LinForm> = by_value.iter().map(|(_, f)| *f).collect();
            let roots = if !self.problem.extended_precision() {
                None
            } else if self.load.is_affine() {
                self.refined_roots(&cur, &forms)
            } else if self.load.basis_vectors().is_some() {
                self.refined_basis_roots(&cur, pt.alpha, &forms)
            } else {
                None
            };
            // (in the unit of α over which the load changes by the point's force scale: not
            // relative to α itself, which a translated α axis makes large)
            let apart = RESOLVED_APART * self.alpha_unit(&pt, self.force_scale(&pt));
            for (k, (guard, _)) in by_value.into_iter().enumerate() {
                let own = roots
                    .as_ref()
                    .and_then(|r| r[k])
                    .is_some_and(|a| (a - pt.alpha).abs() > apart);
                if own {
                    resolved.push(guard);
                } else {
                    nodes.push(guard.node);
                }
            }
        }
        nodes.sort_unstable();
        nodes.dedup();
        // (for the candidates of this point only)
        *self.resolved.borrow_mut() = resolved;
        let entry = self.point_at(cur.lam.clone(), cur.alpha)?;
        let pt = self.snap_to_vertex(pt, &tol, &entry, &cur.classes, &crossing)?;
        let back = Some((cur.classes.as_slice(), cur.t.as_slice()));
        let usual = Widen::USUAL;
        let mut blockers = Vec::new();
        // After pieces a rounding long (transitions a rounding apart, see below), the
        // pieces before them contain the point too, within the thresholds, and walked
        // backwards they enter their regions: that is the way the path came, not a
        // branch, and it is taken only where no retry below finds another continuation.
        // Mirrored nodes in double were flagged as bifurcations, one and two pieces back;
        // and where that walk back was the only piece found, it used to be taken at once
        // (a symmetric body of 1002 contact nodes in double, F = 5, under an oscillating
        // load: one node of a mirrored pair lifted off alone, on a piece of length 0, its
        // image's λν at zero by rounding; the path took the walk back as a fold and
        // retraced 2000 events, to a closed loop), where the retries below switch the
        // image too, as double-double does. Only across such pieces: a path that comes
        // back to a bifurcation point along pieces of some length may go on along one it
        // walked the other way.
        // The path's last pieces before the current one, the latest first; the walk back
        // along the first `recent` of them is the way the path came. `looped`: under a
        // nonlinear load, the current piece a rounding long in the forces (whatever its
        // length in α).
        let (last, recent, looped): (Vec<(Vec<Class>, i8)>, usize, bool) = {
            // (the forces' change against the point's force scale, as `rounding_short`
            // measures it: their rounding is relative to the load's terms, not to the
            // forces, which can be far smaller. Against the forces alone, a mirrored pair
            // in double (721 contact nodes, F = 0.1, oscillating load) that switched
            // 9.1e-13 apart in α, its forces moving by 5e-8 of their size and 9e-10 of the
            // force scale, took the walk back for a second continuation: the first event
            // was flagged as a bifurcation that double-double does not have.)
            let scale = self.force_scale(&pt);
            let still = |l0: &[f64], l1: &[f64]| {
                max_abs_diff(l0, l1) <= ROUNDING_LONG * scale.max(inf_norm(l0)).max(inf_norm(l1))
            };
            let tiny = |a0: f64, a1: f64, l0: &[f64], l1: &[f64]| {
                (a1 - a0).abs() <= ROUNDING_LONG * a0.abs().max(1.0) && still(l0, l1)
            };
            // The piece before the current one is walked back across the current one
            // under an affine load always, else wherever the current piece is a rounding
            // long in α: the two pieces' solution sets meet at the current piece's start,
            // and a point of the current one beyond it on the one before too would make
            // them one (two lines; under a nonlinear load, two curves, which meet twice
            // only where the load comes back, over more than a rounding in α). So where
            // the point fits that piece, it is to the thresholds only. In double, on a
            // mirror-symmetric body (571 contact nodes, F = 5, oscillating load) a
            // mirrored pair, sticking, slipped for 2.5e-9 in α (its forces moving by 1e-7
            // of the force scale) and lifted off, its tangential displacements at a third
            // of their threshold; on another (430 contact nodes, F = 5, affine load) a
            // pair slipped for 1.1e-6 in α (4.8e-7 of it), its tangential displacements at
            // a fifth of their threshold. Both times stick fitted the point again, the way
            // back along the sticking piece was taken for a second continuation, and the
            // lift-off was flagged as a bifurcation that double-double does not have.
            // A current piece whose forces moved by a rounding only counts as a rounding
            // long too: under a nonlinear load that turns there, its α may be noise (a
            // basis load turning 1e-10, relative in φ, past a lift-off: the node's gap
            // was taken to close again 2.6e-6 in α later, the forces moving by 1e-10 of
            // their scale, and the walk back along the slipping piece was taken as a fold).
            let tr = self.trace.as_ref().expect("started");
            let n = tr.pieces.len().saturating_sub(1);
            let pieces = &tr.pieces[n.saturating_sub(RETRACE_LOOKBACK)..n];
            let mut recent = 0;
            let cur_still = still(&cur.lam, &pt.lam);
            let mut across = self.load.is_affine()
                || (pt.alpha - cur.alpha).abs() <= ROUNDING_LONG * cur.alpha.abs().max(1.0)
                || cur_still;
            for p in pieces.iter().rev() {
                if !across {
                    break;
                }
                recent += 1;
                // (the stored pieces keep their forces in the user's units)
                let (l0, l1) = (
                    self.lam_to_internal(&p.lambda_from),
                    self.lam_to_internal(&p.lambda_to),
                );
                across = tiny(p.alpha_from, p.alpha_to, &l0, &l1);
            }
            let last = pieces
                .iter()
                .rev()
                .map(|p| (p.classes.clone(), p.direction))
                .collect();
            let looped = !self.load.is_affine() && cur_still;
            (last, recent, looped)
        };
        // (whether `cd` walks back along one of `pieces`)
        let walks_back = |cd: &Candidate, pieces: &[(Vec<Class>, i8)]| {
            let t_alpha = cd.t.last().copied().unwrap_or(0.0);
            pieces.iter().any(|(classes, direction)| {
                cd.classes == *classes && t_alpha * f64::from(*direction) < 0.0
            })
        };
        let retraces = |cd: &Candidate| walks_back(cd, &last[..recent]);
        let without_retrace = |mut cands: Vec<Candidate>| {
            cands.retain(|cd| !retraces(cd));
            cands
        };
        // A node that fits no class at the usual thresholds may fit one at the widened
        // ones below: the error is returned only where those find no continuation either.
        let (mut cands, mut unfit) = match self.continuations_either(
            &pt,
            &cur.classes,
            &nodes,
            back,
            &mut blockers,
            usual,
        ) {
            Ok(cands) => (cands, None),
            Err(e) => (Vec::new(), Some(e)),
        };
        // (the walk back kept for the last resort below)
        let mut walked_back: Vec<Candidate>;
        (cands, walked_back) = cands.into_iter().partition(|cd| !retraces(cd));
        // Where several continuations remain, one walking back along one of the path's
        // last pieces across pieces of some length counts only where that piece passes
        // through the point: its own point at α fits its classes to the widest
        // thresholds. Under a nonlinear load two pieces' solution sets may meet twice,
        // but where the point fits the piece before the current one to the thresholds
        // only, its own point lies off its region by the way the piece moved since.
        // On a mirror-symmetric body in double (491 contact nodes, F = 0.8, oscillating
        // load) a mirrored pair, sticking, slipped for 2.1e-8 in α and lifted off with its
        // tangential displacements at a seventh of their threshold: stick walked back was
        // a second continuation, the lift-off flagged as a bifurcation (8 in two periods)
        // that double-double does not have.
        if cands.len() > 1 {
            let widest = self.tol_at(&pt).widened(WIDEST);
            let off: Vec<Candidate>;
            (cands, off) = std::mem::take(&mut cands)
                .into_iter()
                .partition(|cd| !walks_back(cd, &last) || self.passes_through_at(&pt, cd, &widest));
            walked_back.extend(off);
        }
        // A node that the way in found clear of zero (its guard crossing a step beyond
        // `zero_tol` along the old piece) may be at zero and leaving along every
        // neighbouring piece: it switches here too. Transitions a rounding apart look like
        // that: mirrored nodes of a symmetric body in double, whose W is symmetric to
        // rounding only, crossed 9.6e-12 apart in arclength (zero_tol 1e-11), and no piece
        // with one of them switching continued the path.
        blockers.retain(|i| !nodes.contains(i));
        if cands.is_empty() && !blockers.is_empty() {
            nodes.append(&mut blockers);
            nodes.sort_unstable();
            nodes.dedup();
            let again =
                self.continuations_either(&pt, &cur.classes, &nodes, back, &mut blockers, usual)?;
            cands = without_retrace(again);
        }
        // A single continuation at the usual thresholds that the data do not determine: a
        // switching node fits other classes where no displacement row's threshold is
        // below how far the data determine q (`determined`). On a
        // mirror-symmetric body in double, the node on the axis touched down with a
        // tangential displacement of 1e-14 of the load's scale (0 by symmetry): stick did
        // not fit and slip did, and the path slipped for 2e-12 in α before it stuck (two
        // events for one, the second flagged as a bifurcation). There the widened
        // thresholds block slip (its guard is at zero and leaving) and take stick: where
        // they find exactly one continuation, it is taken. Only where the usual
        // continuation is itself a rounding long (`rounding_short`): a touchdown with a
        // small tangential displacement of general data slips first, then sticks. On
        // slender strips under random loads a node touched down with 7.7e-9 (force units)
        // below a floor of 2e-7 and would slip for 1.9e-4 in α: taking stick there lost
        // that slip (the independent reference has it), or the path stopped at the next
        // transition with the node fitting no class at the usual thresholds.
        if cands.len() == 1 && self.rounding_short(&pt, &cands[0], &nodes) {
            let mut taken = false;
            if let Some(widen) = self.undetermined_fit(&pt, &nodes)
                && let Ok(wider) =
                    self.continuations_either(&pt, &cur.classes, &nodes, back, &mut blockers, widen)
            {
                let wider = without_retrace(wider);
                if wider.len() == 1 {
                    cands = wider;
                    taken = true;
                }
            }
            // Where the forces too are at zero only to the data's accuracy (the widest
            // thresholds fit the switching nodes to classes the usual ones do not): the
            // first of the last-resort thresholds (`widening`) with exactly one
            // continuation that is not itself a rounding long is taken. On a
            // mirror-symmetric body in double (721 contact nodes, F = 0.1, oscillating
            // load), the node on the axis, the last in contact, reached its stick cone
            // 1.4e-13 in α before its λν reached 0 (its λt, 0 by symmetry, was 1.8e-12 of
            // the force scale, within how far the data determine it; λν at the cone's edge
            // is that over F): it slipped for 1.4e-13 and then lifted off, two events and a
            // slip that double-double, and the symmetry, do not have.
            if !taken {
                let tol = self.tol_at(&pt);
                let usual_fit = self.compatible(&nodes, &pt, &tol);
                if self.compatible(&nodes, &pt, &tol.clone().widened(WIDEST)) != usual_fit {
                    for widen in self.widening(&pt) {
                        let Ok(mut lasting) = self.widened_continuations(
                            &pt,
                            &cur.classes,
                            &nodes,
                            back,
                            &mut blockers,
                            widen,
                            &retraces,
                        ) else {
                            continue;
                        };
                        lasting.retain(|cd| !self.rounding_short(&pt, cd, &nodes));
                        if lasting.len() == 1 {
                            cands = lasting;
                            break;
                        }
                    }
                }
            }
        }
        // The last resort where the usual thresholds find no continuation or several, as
        // the point may carry more rounding, or the data determine it less well, than they
        // assume (`widening`): an open node's λt against 1 + F times its threshold (its λν
        // is at zero to its threshold, and |λt| ≤ F λν: with F = 5 a slipping node lifting
        // off with its mirror image, λν at 0.84 of its threshold, did not fit open), then
        // no displacement row's threshold below how far the data determine q's rows, then
        // all thresholds 4, 16, 64 times wider as far as the forces are undetermined (in
        // double only), last the determined ones with the cone's. The
        // first that finds exactly one continuation is taken; else what the usual
        // thresholds found. (Where they found none, the first widening that found several
        // used to be taken: reached by no test, and in sweeps of 2,300 traces only once, on
        // a strip in double (`fe_strip` seed 1597, κ(W) = 1e8), where it took a piece that
        // led the path back onto its own and ended it as a closed loop that the path does
        // not have; without it that trace failed loudly, "node 59 fits no class", until
        // the cone's thresholds came first: it now follows the reference.)
        // On mirror-symmetric bodies, whose W and q are symmetric to about κ(A) ε only:
        // the node on the axis touched down with a tangential displacement of 1.6e-14 of
        // the load's scale (0 by symmetry) and no class fitted it; in double a mirrored
        // node's contact forces came out 1.2e-11 of the forces apart from its image's
        // (zero_tol 1e-11), and the class its image took did not fit it; and the node on
        // the axis, lifting off, reached its stick cone 3.6e-11 of the forces before λ = 0
        // (its λt is rounding there), where slip in either direction continued the path: a
        // bifurcation, and the path stopped, where it lifts off.
        //
        // In extended precision a widened candidate must also contain the point: its own
        // point at α, refined, must fit its classes to the widened thresholds. The
        // thresholds widened to how far the data determine q (κ(A) ε = 2.6e-4 of the load
        // on a 1201 × 11 strip on 120 × 0.3, F = 5) let a node at a fold whose dt was
        // 100 times its usual threshold stick, where two continuations fitted the usual
        // thresholds; that piece's own point lay 9e-5 outside its stick cone (forces of
        // 1e-2), and the path went on along it until a node fitted no class.
        if cands.len() != 1 {
            // Where the usual thresholds found several continuations, a widened one must
            // fit the point to at most MAX_WIDENING times the usual thresholds (an open
            // node's λt against F times that): widening resolves bifurcations that are
            // rounding artefacts, not genuine ones. Two decoupled copies of a strip
            // (F = 5, extended precision) meet a fold of the strip as a bifurcation of three
            // pieces (the pair's solution set crosses itself there); the thresholds widened
            // to how far the data determine q let a node touching down with a tangential
            // displacement of 1.5e-4 (the largest of any node) stick, the single piece
            // found so was taken, and the fold of each copy was skipped.
            let several = if cands.len() > 1 {
                Some(self.compatible(&nodes, &pt, &self.tol_at(&pt).widened(WIDEST)))
            } else {
                None
            };
            for widen in self.widening(&pt) {
                let mut wider = match self.widened_continuations(
                    &pt,
                    &cur.classes,
                    &nodes,
                    back,
                    &mut blockers,
                    widen,
                    &retraces,
                ) {
                    Ok(wider) => wider,
                    Err(e) => {
                        unfit.get_or_insert(e);
                        continue;
                    }
                };
                if let Some(fits) = &several {
                    wider.retain(|cd| {
                        nodes
                            .iter()
                            .zip(fits)
                            .all(|(&i, fit)| fit.contains(&cd.classes[i]))
                    });
                }
                if wider.len() == 1 {
                    cands = wider;
                    break;
                }
            }
        }
        // In double, a node off `nodes` whose guard is at zero only to the data's accuracy
        // (within 4 times the usual thresholds, where the data leave the forces
        // undetermined by more) may belong to a degenerate point whose nodes rounding has
        // put apart. Where the nodes switching with it give two or more continuations that
        // keep the path's orientation, the point is a bifurcation where the path stops, as
        // it does in double-double: on a mirror-symmetric body in double (660 contact
        // nodes, F = 5, oscillating load) a node and its image reached their cone's edge
        // 2.1e-13 apart (3.3 times the usual threshold), where double-double finds three
        // continuations, two keeping the orientation; the node alone was taken, and the
        // path went on along an asymmetric branch, unflagged. Elsewhere the path is left
        // as it was: at regular transitions of mirrored pairs the widened thresholds let
        // through pieces that double-double does not, and two bodies had such transitions
        // flagged as bifurcations where the path went on.
        // (How far the data determine q costs a few solves with A, once per path: only
        // where a guard is that near zero at 4 times the usual thresholds alone.)
        if cands.len() == 1 && !self.problem.extended_precision() {
            // (`c` again: the one above borrows `self` across its mutable uses since)
            let c = self.consts();
            let rows = self.guard_table(&cur.classes, &pt, None);
            let tol = self.tol_at(&pt);
            let near = |widen: Widen| -> Vec<usize> {
                let tol = tol.clone().widened(widen);
                rows.iter()
                    .filter(|row| {
                        !nodes.contains(&row.guard.node)
                            && tol.within(&c.guard_form(row.guard), row.value.abs())
                    })
                    .map(|row| row.guard.node)
                    .collect()
            };
            // (the first of `widening`'s steps by a factor, where it has one)
            if !near(Widen { k: 4.0, ..usual }).is_empty()
                && let Some(widen) = self.widening(&pt).into_iter().find(|w| w.k == 4.0)
            {
                let mut all = nodes.clone();
                all.extend(near(widen));
                all.sort_unstable();
                all.dedup();
                if let Ok(wider) =
                    self.continuations_either(&pt, &cur.classes, &all, back, &mut blockers, widen)
                {
                    let wider = without_retrace(wider);
                    let sigma = self.trace.as_ref().expect("started").sigma;
                    if wider.iter().filter(|cd| cd.orientation == sigma).count() > 1 {
                        cands = wider;
                        nodes = all;
                    }
                }
            }
        }
        // Where no retry found another continuation, the way back after all: on the
        // 2001 × 3 strip on 200 × 0.2 (F = 1, double-double) near α = −2 the path holds
        // from the data along it (`python/tests/test_from_data.py`).
        // Not under a nonlinear load where every way back retraces the path across pieces
        // a rounding long, the current one included (in the forces, see `looped`): the
        // path would go back over what it has traced, along the piece it left a rounding
        // ago, which a path of solutions does not do (no test or sweep takes that way
        // back). Under a basis load turning 1e-10 (relative, in φ) past a lift-off, the
        // node's gap, rising to 4e-17 about the turn (its rounding 5e-16), was taken to
        // close again 1.9e-13 in α after it opened: the way back along the slipping
        // piece was the only continuation, and the path went back to the window's start
        // without an error.
        let loops_back = cands.is_empty()
            && looped
            && !walked_back.is_empty()
            && walked_back.iter().all(retraces);
        if cands.is_empty() && !loops_back {
            cands = walked_back;
        }
        self.close_piece(&pt);
        let (events_start, pieces_len, last_dir, sigma) = {
            let tr = self.trace.as_ref().expect("started");
            (tr.events.len(), tr.pieces.len(), tr.last_dir, tr.sigma)
        };
        if cands.is_empty() {
            if loops_back {
                return Err(Error::Numerical(format!(
                    "at alpha = {:e} the only continuation walks back along the path's own pieces: node(s) {:?} switched there and back within a rounding of the forces, and the path would retrace itself; under this nonlinear load a guard of theirs stays within its rounding of zero about here (a load that turns, or is nearly stationary, within the data's resolution of a transition)",
                    pt.alpha,
                    nodes.iter().map(|i| i + 1).collect::<Vec<_>>()
                )));
            }
            if let Some(e) = unfit {
                return Err(e);
            }
            return Err(Error::Numerical(format!(
                "no neighbouring piece continues the path at alpha = {:e} (nodes {:?}){}{}",
                pt.alpha,
                nodes.iter().map(|i| i + 1).collect::<Vec<_>>(),
                near_overflow(&pt),
                self.unresolved_friction_hint(&pt, &nodes)
            )));
        }
        let bifurcation = cands.len() > 1;
        let choice = if bifurcation {
            let keep: Vec<usize> = (0..cands.len())
                .filter(|&k| cands[k].orientation == sigma)
                .collect();
            if keep.len() == 1 { Some(keep[0]) } else { None }
        } else {
            Some(0)
        };
        let branches: Vec<Branch> = cands
            .iter()
            .map(|c| c.branch(c.orientation == sigma))
            .collect();
        let pending = PendingJoin {
            point: pt,
            from: cur.classes.clone(),
            cands,
            events_start,
            pieces_len,
            last_dir,
            bifurcation,
            at_start: false,
        };
        {
            let tr = self.trace.as_mut().expect("started");
            tr.branches = if bifurcation { branches } else { Vec::new() };
            tr.transitions += 1;
        }
        match choice {
            Some(k) => {
                let out = self.apply(&pending, k)?;
                self.trace.as_mut().expect("started").pending = Some(pending);
                Ok(out)
            }
            None => {
                // Stop at the bifurcation point; its events are recorded when the caller
                // chooses a branch.
                let tr = self.trace.as_mut().expect("started");
                tr.cur.lam = pending.point.lam.clone();
                tr.cur.alpha = pending.point.alpha;
                tr.pending = Some(pending);
                Ok(self.finish(EndReason::Bifurcation))
            }
        }
    }

    /// At a point where every contact force vanishes (the load passes through a state of
    /// zero contact forces), the exit point found from one guard carries that guard's
    /// rounding, relative to the magnitudes along the piece; where those vanish too (a
    /// load proportional to α at α = 0) every threshold at the point is far below that
    /// rounding. The exact point is `λ = 0` at the α where the load reaches that state:
    /// - where every node is at the vertex (`q(α) = (g, 0)`), the α that minimises
    ///   `‖q(α) − (g, 0)‖` (closed form for an affine load; the point's α otherwise);
    /// - under an affine load, where the nodes open on the piece (`classes`) keep their
    ///   gaps: the α that minimises it on the rows the piece holds at zero (both rows of
    ///   a sticking node, the normal row of a slipping one), or, where the piece has no
    ///   node in contact, the root of the crossing guard's gap, `q_k(α) = g_k`. A curved
    ///   body touching the foundation at one node with zero gap (the apex) under a load
    ///   proportional to α has that node alone at the vertex at α = 0: unloaded through
    ///   it, the node's λt (rounding of the piece's solves, relative to the forces at the
    ///   piece's entry) fitted no class at the point's thresholds, which are relative to
    ///   a load of size 0; loaded through it from above, the touchdown's gap came out as
    ///   α's rounding times q', above those thresholds, and no piece continued the path.
    ///
    /// Each snapped α must put the rows it is taken from within the thresholds, and every
    /// guard of the piece must be above minus its threshold at the snapped point. Other
    /// points are returned unchanged. "Vanishes" is judged against the forces along the
    /// piece the path came by (`entry`: the point where it entered it), not against the
    /// point's own: there the forces are rounding noise of the piece's solves, as large as
    /// themselves, and no class would fit them. Under an affine load a point whose forces
    /// are within [`NEAR_VANISHING`] of that scale is moved too, where the snapped α lies
    /// within that fraction of the piece's length in α from it: the piece's λ is affine in
    /// α, and where `λ = 0` solves its equations at α* (the rows above vanish there) its
    /// guards on λ all cross at α*; their computed roots carry the error of the piece's
    /// tangent times the piece's length.
    pub(super) fn snap_to_vertex(
        &mut self,
        pt: Point,
        tol: &Tol,
        entry: &Point,
        classes: &[Class],
        crossing: &[Guard],
    ) -> Result<Point> {
        let p = self.problem.p();
        let z = self.opts.zero_tol;
        let reference = self.force_scale(&pt).max(self.force_scale(entry));
        let forces = inf_norm(&pt.lam);
        let loose = tol.disp.max(z * reference);
        let vanished = forces <= loose;
        let affine = self.load.is_affine();
        // Under an affine load the point may also be near one where the forces vanish:
        // the piece's λ is affine in α, and its roots carry the error of the piece's
        // tangent (cond · ε) times the piece's length in α, not only rounding.
        let near = affine && forces <= NEAR_VANISHING * reference;
        if !vanished && !near {
            return Ok(pt);
        }
        let m = 2 * p;
        // The rows the snapped point must hold at zero, each set tried in turn.
        let mut row_sets: Vec<Vec<usize>> = vec![(0..m).collect()];
        if affine {
            let held: Vec<usize> = classes
                .iter()
                .enumerate()
                .flat_map(|(i, &c)| match c {
                    Class::Open => vec![],
                    Class::Stick => vec![i, p + i],
                    Class::SlipPlus | Class::SlipMinus => vec![i],
                })
                .collect();
            if held.is_empty() {
                // A gap guard of an open node crossing (on a piece with no contact force
                // λ = 0 exactly, and the gap is q_k(α) − g_k).
                row_sets.extend(
                    crossing
                        .iter()
                        .filter(|g| classes[g.node] == Class::Open)
                        .map(|g| vec![g.node]),
                );
            } else if held.len() < m {
                row_sets.push(held);
            }
        }
        // An affine load's parts, `q0 − (g, 0)` and `q1`, for α* in closed form.
        let parts = if affine {
            let (q0, q1) = self.load.q(0.0, self.problem.delassus())?;
            Some((shift_gap(&q0, self.problem.gap_equilibrated()), q1))
        } else {
            None
        };
        for rows in row_sets {
            let alpha = if let Some((qg, q1)) = &parts {
                // α* = −(q0 − g)·q1 / |q1|² on those rows: exactly 0 for a homogeneous
                // load (q0 = g = 0 there), where every tolerance at the vertex is relative
                // to zero. Both parts are divided by their largest entry first: the squares
                // of loads beyond 1e154 overflow (α* was inf / inf = NaN there, and a NaN
                // point passed the test below).
                let s = rows
                    .iter()
                    .fold(0.0f64, |a, &k| a.max(qg[k].abs()).max(q1[k].abs()));
                let (num, den) = rows.iter().fold((0.0, 0.0), |(a, b), &k| {
                    let (x, y) = (qg[k] / s, q1[k] / s);
                    (a + x * y, b + y * y)
                });
                // (+ 0.0: a homogeneous load's α* = −0 / den is reported as 0)
                let alpha = -num / den + 0.0;
                if den > 0.0 && alpha.is_finite() {
                    alpha
                } else {
                    pt.alpha
                }
            } else {
                pt.alpha
            };
            let snapped = self.point_at(vec![0.0; m], alpha)?;
            let qg = shift_gap(&snapped.q, self.problem.gap_equilibrated());
            let off = rows.iter().fold(0.0f64, |a, &k| a.max(qg[k].abs()));
            let close = vanished
                || (alpha - pt.alpha).abs() <= NEAR_VANISHING * (entry.alpha - pt.alpha).abs();
            if !(qg.iter().all(|v| v.is_finite())
                && self.problem.default_r() * off <= loose
                && close)
            {
                continue;
            }
            // The snapped point must lie on the piece: no guard of it below zero beyond
            // its threshold (a node whose gap closed between the point and the snapped α
            // has its own transition there).
            let c = self.consts();
            let inside = self
                .guard_table(classes, &snapped, None)
                .iter()
                .all(|g| tol.within(&c.guard_form(g.guard), -g.value));
            if inside {
                return Ok(snapped);
            }
        }
        Ok(pt)
    }

    /// An error where `classes` take a node with F > 0 from one slip class straight to the
    /// other while its normal force is far from zero ([`UNRESOLVED_CONE`] times its
    /// threshold). Between slip− and slip+ such a node sticks while λt crosses its cone,
    /// a change of 2 F |λν|. That both slip classes fit it at one point means F |λν| is
    /// within the threshold of the forces: its friction is too small for `zero_tol` to
    /// resolve (`tests/core_small_friction.rs`: with F = 1e-10, traces went on past such
    /// events to the window, every state solving the problem to 1e-6, where the reference
    /// tracer finds a stick phase about 1e-10 of α long).
    fn unresolved_cone(&self, pend: &PendingJoin, classes: &[Class]) -> Result<()> {
        use Class::{SlipMinus, SlipPlus};
        if pend.at_start {
            // the branches leaving the start record no events
            return Ok(());
        }
        let pt = &pend.point;
        let Some((i, lam_n)) = (0..classes.len()).find_map(|i| {
            matches!(
                (pend.from[i], classes[i]),
                (SlipMinus, SlipPlus) | (SlipPlus, SlipMinus)
            )
            .then(|| self.unresolved_friction(pt, i).map(|l| (i, l)))
            .flatten()
        }) else {
            return Ok(());
        };
        let friction = self.consts().friction;
        let scale = self.force_scale(pt);
        Err(Error::Numerical(format!(
            "node {} changes from {} to {} at alpha = {:e} without the stick phase between them: \
             its friction coefficient F = {:e} ({:e} on its equilibrated rows) times its normal \
             force is {:.1e} of the contact forces' scale, within zero_tol = {:e} of it, while \
             the normal force is {:.1e} of that scale. Stick, slip+ and slip- all fit the node \
             there, and the stick phase is not resolved: a node with this little friction is \
             frictionless at this zero_tol. Give it F = 0, or trace with a smaller zero_tol",
            i + 1,
            pend.from[i],
            classes[i],
            pt.alpha,
            self.problem.friction()[i],
            friction[i],
            friction[i] * lam_n / scale,
            self.opts.zero_tol,
            lam_n / scale,
        )))
    }

    /// Node i's |λν| at `pt` where its friction is not resolved there: F > 0, F |λν|
    /// within the widest retry's force threshold, and |λν| above [`UNRESOLVED_CONE`] times
    /// it (a node whose normal force is at zero has no friction to resolve). None else.
    fn unresolved_friction(&self, pt: &Point, i: usize) -> Option<f64> {
        let c = self.consts();
        if c.frictionless(i) {
            return None;
        }
        let f = c.friction[i];
        let thr = self.tol_at(pt).of(&c.guard_form(Guard {
            node: i,
            kind: crate::piece::GuardKind::Compress,
        }));
        let lam_n = pt.lam[i].abs();
        (lam_n > UNRESOLVED_CONE * thr && f * lam_n <= MAX_WIDENING * thr).then_some(lam_n)
    }

    /// For an error at `pt` among `nodes`: a sentence naming the first node whose friction
    /// is not resolved there ([`Self::unresolved_friction`]), else "".
    fn unresolved_friction_hint(&self, pt: &Point, nodes: &[usize]) -> String {
        nodes
            .iter()
            .find(|&&i| self.unresolved_friction(pt, i).is_some())
            .map_or(String::new(), |&i| {
                format!(
                    "; node {}'s friction coefficient F = {:e} times its normal force is within \
                     the thresholds of the forces there (zero_tol = {:e}), so its stick \
                     phases are not resolved: give it F = 0, or trace with a smaller zero_tol",
                    i + 1,
                    self.problem.friction()[i],
                    self.opts.zero_tol
                )
            })
    }

    /// Moves onto candidate `k` of a pending transition and records its events. Errors:
    /// see [`Self::unresolved_cone`].
    pub(super) fn apply(&mut self, pend: &PendingJoin, k: usize) -> Result<StepOutcome> {
        let cand = pend.cands[k].clone();
        self.unresolved_cone(pend, &cand.classes)?;
        self.commit_solver(&cand.lu);
        let mut pt = pend.point.clone();
        self.consts()
            .satisfy_local(&pend.from, &cand.classes, &mut pt.lam);
        let dir = cand.direction();
        let fold = dir != 0 && pend.last_dir != 0 && dir != pend.last_dir;
        let scale = self.force_scale(&pt);
        let a_s = cand.scales.alpha;
        let p = self.problem.p();
        let snapshot = self.load.snapshot(pt.alpha)?;
        let user = self.lam_to_user(&pt.lam);
        let tr = self.trace.as_mut().expect("started");
        tr.events.truncate(pend.events_start);
        tr.event_loads.truncate(pend.events_start);
        tr.pieces.truncate(pend.pieces_len);
        let transition = tr.events.last().map(|e| e.transition + 1).unwrap_or(0);
        for i in 0..cand.classes.len() {
            if cand.classes[i] != pend.from[i] {
                let index = tr.events.len();
                tr.events.push(Event {
                    index,
                    transition,
                    alpha: pt.alpha,
                    node: i,
                    from: pend.from[i],
                    to: cand.classes[i],
                    fold,
                    bifurcation: pend.bifurcation,
                    lambda_n: user[..p].to_vec(),
                    lambda_t: user[p..].to_vec(),
                    classes: cand.classes.clone(),
                });
                tr.event_loads.push(snapshot.clone());
            }
        }
        tr.pieces.push(PieceRecord {
            classes: cand.classes.clone(),
            alpha_from: pt.alpha,
            alpha_to: pt.alpha,
            lambda_from: user.clone(),
            lambda_to: user.clone(),
            direction: dir,
            orientation: cand.orientation,
            det_sign: cand.det_sign,
        });
        if dir != 0 {
            tr.last_dir = dir;
        } else {
            tr.last_dir = pend.last_dir;
        }
        let same_point = tr.cur.alpha == pt.alpha
            && tr
                .cur
                .lam
                .iter()
                .zip(&pt.lam)
                .all(|(a, b)| (a - b).abs() <= 1e-14 * scale);
        tr.zero_steps = if same_point { tr.zero_steps + 1 } else { 0 };
        tr.cur = CurrentPiece {
            classes: cand.classes.clone(),
            lam: pt.lam.clone(),
            alpha: pt.alpha,
            t: cand.t.clone(),
            lu: cand.lu.clone(),
            scales: cand.scales,
            rate: cand.rate.clone(),
            xp: cand.xp.clone(),
        };
        let events = pend.events_start..tr.events.len();
        let key = classes_hash(&cand.classes);
        let closed = tr.entry_index.get(&key).is_some_and(|ks| {
            ks.iter().any(|&k| {
                let e = &tr.entries[k];
                e.classes == cand.classes
                    && (e.alpha - pt.alpha).abs() <= 1e-9 * a_s
                    && e.lam
                        .iter()
                        .zip(&pt.lam)
                        .all(|(x, y)| (x - y).abs() <= 1e-9 * scale)
            })
        });
        tr.entry_index
            .entry(key)
            .or_default()
            .push(tr.entries.len());
        tr.entries.push(PieceEntry {
            classes: cand.classes.clone(),
            lam: pt.lam.clone(),
            alpha: pt.alpha,
        });
        if closed {
            tr.end = Some(EndReason::ClosedLoop);
        } else if tr.zero_steps > 16 {
            tr.end = Some(EndReason::Failed(format!(
                "the path cycles between pieces at alpha = {:e} without moving",
                pt.alpha
            )));
        }
        Ok(StepOutcome::Transition {
            events,
            fold,
            bifurcation: pend.bifurcation,
        })
    }

    /// Records a bifurcation at the start point: `cands` (the first taken) all leave it
    /// toward alpha_end.
    pub(super) fn offer_start_branches(&mut self, pt: Point, cands: Vec<Candidate>) {
        let tr = self.trace.as_mut().expect("started");
        tr.branches = cands.iter().map(|c| c.branch(true)).collect();
        tr.pending = Some(PendingJoin {
            point: pt,
            from: cands[0].classes.clone(),
            cands,
            events_start: 0,
            pieces_len: 0,
            last_dir: tr.last_dir,
            bifurcation: true,
            at_start: true,
        });
    }

    /// Continue along candidate `k` of [`Path::branches`] instead of the one taken (or
    /// after the path stopped with [`EndReason::Bifurcation`]). Only allowed directly after
    /// the bifurcation step, or directly after [`Path::start`] when it offered branches
    /// (the path then starts again at the same point on branch `k`). Errors: not started,
    /// no bifurcation pending, `k` out of range.
    pub fn choose_branch(&mut self, k: usize) -> Result<()> {
        let _pool = self.pool_scope();
        let tr = self
            .trace
            .as_mut()
            .ok_or_else(|| Error::Usage("the path has not been started".into()))?;
        let Some(pend) = tr.pending.take() else {
            return Err(Error::Usage(
                "no bifurcation is pending: choose a branch directly after the step that found it"
                    .into(),
            ));
        };
        if !pend.bifurcation {
            tr.pending = Some(pend);
            return Err(Error::Usage(
                "the last transition was not a bifurcation".into(),
            ));
        }
        if k >= pend.cands.len() {
            let n = pend.cands.len();
            tr.pending = Some(pend);
            return Err(Error::Usage(format!(
                "branch {k} does not exist ({n} candidates)"
            )));
        }
        if tr.end == Some(EndReason::Bifurcation) {
            tr.end = None;
        }
        if pend.at_start {
            let want = sign(self.opts.alpha_end - self.opts.alpha_start);
            let branches = std::mem::take(&mut tr.branches);
            let res = self.begin_afresh(&pend.point, pend.cands[k].clone(), want);
            let tr = self.trace.as_mut().expect("started");
            tr.branches = branches;
            tr.pending = Some(pend);
            return res;
        }
        let res = self.apply(&pend, k);
        let tr = self.trace.as_mut().expect("started");
        tr.pending = Some(pend);
        res.map(|_| ())
    }
}

#[cfg(test)]
mod tests {
    use super::FIRST_PASS_REFUSES;
    use crate::{Class, EndReason, Load, Path, PathOptions, ProblemBuilder};
    use std::sync::Arc;

    /// Decoupled nodes (W = I/2, F = 1/2, condensed): `nv` nodes touch down at α = 1/2
    /// (`qν = −1/4 + α/2`, `qt = −1/20 + α/10`) and `ns` nodes, pressed (`qν = 1/2`) and
    /// sheared (`qt = α/2`), reach their cone's edge there. By hand: before α = 1/2 the
    /// touching nodes are open and the sheared ones stick (`λ = −2q`, `|λt| = α ≤ F |λν| =
    /// 1/2`); after it the touching nodes stick (`λ = −2q`, `|λt| = |λν|/5`) and the sheared
    /// ones slip in +t (`λν = −1`, `λt = −1/2`). With 6 nodes at the vertex and 3 at the
    /// cone's edge (4^6 · 2^3 neighbouring pieces, beyond the 4096 enumerated), the vertex
    /// nodes take their classes from the directional problem for each of the 8
    /// combinations of the others'. Here the enumeration's first pass (the solver's first
    /// stages) is made to find nothing, as where only the last stages solve those
    /// directional problems: the pass with every stage must still find the continuation.
    #[test]
    fn the_second_pass_finds_what_the_first_misses() {
        let (nv, ns) = (6, 3);
        let p = nv + ns;
        let w = faer::Mat::<f64>::from_fn(2 * p, 2 * p, |i, j| if i == j { 0.5 } else { 0.0 });
        let problem = Arc::new(
            ProblemBuilder::condensed(w)
                .friction_uniform(0.5)
                .build()
                .expect("problem"),
        );
        let (mut q0, mut q1) = (vec![0.0; 2 * p], vec![0.0; 2 * p]);
        q0[..ns].fill(0.5);
        q1[p..p + ns].fill(0.5);
        q0[ns..p].fill(-0.25);
        q1[ns..p].fill(0.5);
        q0[p + ns..].fill(-0.05);
        q1[p + ns..].fill(0.1);
        FIRST_PASS_REFUSES.set(Some(0));
        let mut path = Path::new(
            problem,
            Load::affine(q0, q1).unwrap(),
            PathOptions::window(0.0, 1.0),
        )
        .expect("path");
        let traced = path.start(0.0, None).and_then(|_| path.run());
        let refused = FIRST_PASS_REFUSES.replace(None).expect("set above");
        traced.expect("trace");
        assert!(refused > 0, "the first pass was never asked");
        assert_eq!(path.end_reason(), Some(&EndReason::Window));
        assert_eq!(path.events().len(), p, "one event per node");
        for e in path.events() {
            assert!((e.alpha - 0.5).abs() <= 1e-15, "event at α = {}", e.alpha);
            let want = if e.node < ns {
                (Class::Stick, Class::SlipPlus)
            } else {
                (Class::Open, Class::Stick)
            };
            assert_eq!((e.from, e.to), want, "node {}", e.node);
        }
        let sols = path.solutions_at(1.0).expect("solutions_at");
        assert_eq!(sols.len(), 1);
        let st = &sols[0].state;
        for i in 0..p {
            let want = if i < ns { (-1.0, -0.5) } else { (-0.5, -0.1) };
            assert!(
                (st.lambda_n[i] - want.0).abs() <= 1e-15
                    && (st.lambda_t[i] - want.1).abs() <= 1e-15,
                "node {i}: λ = ({}, {})",
                st.lambda_n[i],
                st.lambda_t[i]
            );
        }
    }
}
