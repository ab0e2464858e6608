//! Queries on a traced path: the records kept, the state at an event (one back-solve)
//! and every traced solution at a given α.

use super::*;

/// A point whose u [`Path::solve_points`] solves for.
struct SolvePoint<'a> {
    alpha: f64,
    /// λ (internal units).
    lam: Vec<f64>,
    /// The load there.
    load: &'a LoadSnapshot,
}

impl Path {
    /// True after a successful [`Path::start`].
    pub fn is_started(&self) -> bool {
        self.trace.is_some()
    }

    /// Why the path ended, if it did.
    pub fn end_reason(&self) -> Option<&EndReason> {
        self.trace.as_ref().and_then(|t| t.end.as_ref())
    }

    /// How [`Path::start`] reached the start point: the fixed-α solver, or one of its
    /// fallbacks where the solver failed (see [`StartRoute`]). None before the start.
    pub fn start_route(&self) -> Option<StartRoute> {
        self.trace.as_ref().map(|t| t.route)
    }

    /// The full state at the start point: u = A⁻¹ (f(α) + Bᵀλ) and the residual,
    /// computed on request as an event's is ([`Path::event_state`]: with fricont's own
    /// factor and an affine or basis load, by the backward half of a solve only), so a
    /// trace that never asks does not pay for it. Never calls the load's closures.
    /// Errors: not started ([`Error::Usage`]); the solve failed or u overflows.
    pub fn start_state(&self) -> Result<State> {
        let tr = self.trace_ref()?;
        let s = &tr.start;
        let point = SolvePoint {
            alpha: s.alpha,
            lam: s.lam.clone(),
            load: &s.load,
        };
        let mut state = None;
        self.solve_points(std::slice::from_ref(&point), |_, u, lam, residual| {
            state = Some(self.state_with(lam, s.alpha, &s.classes, u.to_vec(), residual));
        })?;
        Ok(state.expect("one point solved"))
    }

    /// The events so far (empty before the start).
    pub fn events(&self) -> &[Event] {
        self.trace
            .as_ref()
            .map(|t| t.events.as_slice())
            .unwrap_or(&[])
    }

    /// The full state at event `k`: u = A⁻¹ (f(α) + Bᵀλ) (with fricont's own factor and an
    /// affine or basis load, by the backward half of a solve only: see
    /// [`Path::event_states`]), and the residual.
    /// Never calls the load's closures: the load at the event was kept when it was found
    /// (nothing for an affine load, the weights for a basis load, f(α) for a general one).
    /// Errors: not started, `k` out of range.
    pub fn event_state(&self, k: usize) -> Result<State> {
        let tr = self.trace_ref()?;
        if k >= tr.events.len() {
            return Err(Error::Usage(format!(
                "event {k} does not exist ({} events)",
                tr.events.len()
            )));
        }
        let mut s = self.event_states(k..k + 1)?;
        Ok(s.remove(0))
    }

    /// The full states of events `range` (as [`Path::event_state`]), with the back-solves
    /// done in blocks of 32 right-hand sides (several times faster per event than one at
    /// a time on large meshes) and one state per transition point (events of one
    /// transition share it). Errors: not started, the range exceeds the events.
    pub fn event_states(&self, range: std::ops::Range<usize>) -> Result<Vec<State>> {
        let tr = self.trace_ref()?;
        let mut states = Vec::with_capacity(range.len());
        self.event_points(range.clone(), |k, u, lam, residual| {
            let e = &tr.events[k];
            states.push(self.state_with(lam, e.alpha, &e.classes, u.to_vec(), residual));
        })?;
        Ok(states)
    }

    /// The residuals of the states at events `range` (as in [`Path::event_states`], whose
    /// `residual` they equal), without keeping u: what a report needs, at a fraction of
    /// the memory traffic on large meshes. Errors: as [`Path::event_states`].
    pub fn event_residuals(&self, range: std::ops::Range<usize>) -> Result<Vec<f64>> {
        let mut out = Vec::with_capacity(range.len());
        self.event_points(range, |_, _, _, r| out.push(r))?;
        Ok(out)
    }

    /// Calls `each(k, u, λ, residual)` for every event `k` in `range`, in order (u empty
    /// without a solve; λ internal, shared by the events of a transition).
    /// One back-solve per transition point (see [`Path::solve_points`]).
    fn event_points(
        &self,
        range: std::ops::Range<usize>,
        mut each: impl FnMut(usize, &[f64], &[f64], f64),
    ) -> Result<()> {
        let tr = self.trace_ref()?;
        if range.end > tr.events.len() || range.start > range.end {
            return Err(Error::Usage(format!(
                "events {}..{} do not exist ({} events)",
                range.start,
                range.end,
                tr.events.len()
            )));
        }
        // One point per transition point in the range (its first event).
        let mut firsts: Vec<usize> = Vec::new();
        for k in range.clone() {
            if firsts
                .last()
                .is_none_or(|&j| tr.events[j].transition != tr.events[k].transition)
            {
                firsts.push(k);
            }
        }
        let points: Vec<SolvePoint> = firsts
            .iter()
            .map(|&k| {
                let e = &tr.events[k];
                let lam: Vec<f64> = e.lambda_n.iter().chain(&e.lambda_t).copied().collect();
                SolvePoint {
                    alpha: e.alpha,
                    lam: self.lam_to_internal(&lam),
                    load: &tr.event_loads[k],
                }
            })
            .collect();
        let mut k_next = range.start;
        self.solve_points(&points, |c, u, lam, residual| {
            // Every event of this point's transition, in order.
            let t = tr.events[firsts[c]].transition;
            while k_next < range.end && tr.events[k_next].transition == t {
                each(k_next, u, lam, residual);
                k_next += 1;
            }
        })
    }

    /// Calls `each(c, u, λ, residual)` for every point `c` of `points`, in order (u empty
    /// without a solve; λ internal): u = A⁻¹ (f(α) + Bᵀλ) by one back-solve per point, in
    /// blocks of 32 right-hand sides with buffers reused between blocks; with fricont's
    /// own factor and an affine or basis load, by the backward half of the solve only
    /// (the load's forward half is kept per load vector). The residuals of a block take
    /// one pass over A. Never calls the load's closures. Errors: the solve failed or u
    /// overflows; out of memory.
    fn solve_points(
        &self,
        points: &[SolvePoint],
        mut each: impl FnMut(usize, &[f64], &[f64], f64),
    ) -> Result<()> {
        let n = self.problem.n();
        let has_solve = self.problem.delassus().has_solve();
        const BLOCK: usize = 32;
        let del = self.problem.delassus();
        let m = 2 * self.problem.p();
        let bs = points.len().clamp(1, BLOCK);
        let nu = if has_solve { n } else { 0 };
        let mut x =
            crate::error::try_zeros(nu, bs, "the right-hand sides of the back-solves for u")?;
        let mut u = crate::error::try_zeros(nu, bs, "the displacements u")?;
        let mut lams = faer::Mat::<f64>::zeros(m, bs);
        let nf = self.problem.delassus().load_len();
        let mut fs = crate::error::try_zeros(nf, bs, "the loads at the points")?;
        let mut scratch = Vec::new();
        // With half solves, only the backward half of each solve is done per point:
        // the load's half is kept per load vector (affine and basis loads).
        let cached = has_solve && del.has_half_solve() && self.load.has_half();
        for (b, block) in points.chunks(BLOCK).enumerate() {
            let kb = block.len();
            for (c, pt) in block.iter().enumerate() {
                let f = fs.col_mut(c).try_as_col_major_mut().expect("contiguous");
                let f = f.as_slice_mut();
                self.load.force_into(pt.alpha, pt.load, f);
                if has_solve {
                    for (i, &l) in pt.lam.iter().enumerate() {
                        lams[(i, c)] = l;
                    }
                    let col = x.col_mut(c).try_as_col_major_mut().expect("contiguous");
                    let col = col.as_slice_mut();
                    if !(cached && self.load.half_solved_into(pt.alpha, pt.load, col)) {
                        col.copy_from_slice(f);
                    }
                }
            }
            if has_solve {
                let mut xs = x.as_mut().subcols_mut(0, kb);
                let mut us = u.as_mut().subcols_mut(0, kb);
                if del.has_half_solve() {
                    if !cached {
                        // A general load: the loads' half here (the columns hold f).
                        del.half_solve(xs.as_mut())?;
                    }
                    del.displacements(xs, lams.as_ref().subcols(0, kb), us)?;
                } else {
                    for (c, pt) in block.iter().enumerate() {
                        let col = xs
                            .as_mut()
                            .col_mut(c)
                            .try_as_col_major_mut()
                            .expect("contiguous");
                        self.problem.b().mul_t_vec_add(&pt.lam, col.as_slice_mut());
                    }
                    del.solve_mat_in_place(xs.as_mut())?;
                    us.copy_from(xs.as_ref());
                }
            }
            let ucol = |c: usize| -> &[f64] {
                if has_solve {
                    u.col(c).try_as_col_major().expect("contiguous").as_slice()
                } else {
                    &[]
                }
            };
            let triples: Vec<(&[f64], &[f64], &[f64])> = block
                .iter()
                .enumerate()
                .map(|(c, pt)| {
                    let f = fs.col(c).try_as_col_major().expect("contiguous").as_slice();
                    (ucol(c), &pt.lam[..], f)
                })
                .collect();
            // One pass over A for the residuals of the whole block.
            let residuals = crate::piece::residuals(&self.problem, &triples, &mut scratch);
            for (c, pt) in block.iter().enumerate() {
                each(b * BLOCK + c, ucol(c), &pt.lam, residuals[c]);
            }
        }
        Ok(())
    }

    /// The pieces so far (the last one is the current piece; empty before the start).
    pub fn pieces(&self) -> &[PieceRecord] {
        self.trace
            .as_ref()
            .map(|t| t.pieces.as_slice())
            .unwrap_or(&[])
    }

    /// The current point (u by one back-solve). Errors: not started, load failure.
    pub fn current(&mut self) -> Result<State> {
        let cur = self.trace_ref()?.cur.clone();
        self.state(&cur.lam, cur.alpha, &cur.classes)
    }

    /// Candidate continuations at the last transition point (empty unless it was a
    /// bifurcation and no step has been taken since), or, directly after
    /// [`Path::start`], the pieces leaving the start point toward `alpha_end` when more
    /// than one does (a bifurcation at the start, for example a zero-force vertex of a
    /// homogeneous load; the path follows the first, [`Path::choose_branch`] another).
    pub fn branches(&self) -> &[Branch] {
        self.trace
            .as_ref()
            .map(|t| t.branches.as_slice())
            .unwrap_or(&[])
    }

    /// Every traced solution at `alpha`: one per traced piece whose α-range contains it
    /// (several past a fold), each by interpolation between the piece's end points for an
    /// affine load (exact: a piece is then a segment), or one solve with the piece matrix
    /// otherwise (O(k m²) by an update of the path's current factorisation when the piece
    /// differs from it in k ≤ m/16 nodes, checked against the data; O(m³) by a fresh LU
    /// beyond that; in extended precision refined in double-double, as the traced points
    /// are), plus one back-solve for u. Points shared by two pieces (transition
    /// points) are reported once. Empty if the traced path never reached `alpha`. Errors:
    /// `alpha` not finite ([`Error::InvalidParameter`]), not started, load failure.
    pub fn solutions_at(&mut self, alpha: f64) -> Result<Vec<Solution>> {
        if !alpha.is_finite() {
            return Err(Error::InvalidParameter(format!(
                "alpha = {alpha} is not finite"
            )));
        }
        let _pool = self.pool_scope();
        let pieces = self.trace_ref()?.pieces.clone();
        let m = 2 * self.problem.p();
        // Matching α with a piece's ends: relative to α and to the piece's own extent,
        // never to the window.
        let pt0 = self.point_at(vec![0.0; m], alpha)?;
        let qg = shift_gap(&pt0.q, self.problem.gap_equilibrated());
        let mut out: Vec<Solution> = Vec::new();
        // Internal λ of the solutions in `out`, for the duplicate test.
        let mut seen: Vec<Vec<f64>> = Vec::new();
        for (k, pc) in pieces.iter().enumerate() {
            let (lo, hi) = (
                pc.alpha_from.min(pc.alpha_to),
                pc.alpha_from.max(pc.alpha_to),
            );
            let a_tol = 1e-12 * alpha.abs().max(hi - lo);
            if !(alpha >= lo - a_tol && alpha <= hi + a_tol) {
                continue;
            }
            let mut lams = Vec::new();
            let continuum = pc.direction == 0;
            if continuum {
                lams.push(self.lam_to_internal(&pc.lambda_from));
                lams.push(self.lam_to_internal(&pc.lambda_to));
            } else if (alpha - pc.alpha_from).abs() <= a_tol {
                lams.push(self.lam_to_internal(&pc.lambda_from));
            } else if (alpha - pc.alpha_to).abs() <= a_tol {
                lams.push(self.lam_to_internal(&pc.lambda_to));
            } else if self.load.is_affine() {
                // Under an affine load a piece is a segment in (λ, α): exact from its ends,
                // no factorisation.
                let s = (alpha - pc.alpha_from) / (pc.alpha_to - pc.alpha_from);
                let lam: Vec<f64> = pc
                    .lambda_from
                    .iter()
                    .zip(&pc.lambda_to)
                    .map(|(a, b)| a + s * (b - a))
                    .collect();
                lams.push(self.lam_to_internal(&lam));
            } else {
                // One solve on the piece: by an update of the path's factorisation where
                // the piece differs from its base in few nodes (O(k m²)), checked against
                // the data; else (or when the check fails) a fresh LU (O(m³)).
                let c = self.consts();
                let w = self.problem.delassus().w();
                let rhs = c.piece_rhs(&pc.classes, &qg);
                let solver = self
                    .updater
                    .borrow()
                    .as_ref()
                    .filter(|u| u.reaches(&pc.classes))
                    .and_then(|u| u.extend(&c, w, &pc.classes, None, &[]))
                    .map(|(u, _)| u);
                let (lam, by_update) = self.piece_solve(&pc.classes, solver.as_ref(), &rhs);
                let updated = solver.filter(|_| by_update);
                // In extended precision refined in double-double, as the march's points
                // are: in double, q(α) of a general load (a solve with A) and the piece
                // solve are each off by their condition times ε (on a strip with
                // κ(W) = 1.6e10 the point was 5.5e-5 of max|λ| off, residual 1e-6). The
                // refinement solves as the point did: by the update where its check
                // passed, else by a fresh LU.
                let lam = self
                    .polish_point_by(&pc.classes, updated.as_ref(), alpha, &lam)
                    .map_or(lam, |(l, _)| l);
                lams.push(lam);
            }
            for lam in lams {
                let pt = Point {
                    lam: lam.clone(),
                    ..pt0.clone()
                };
                let scale = self.force_scale(&pt);
                let dup = seen.iter().any(|l: &Vec<f64>| {
                    l.iter()
                        .zip(&lam)
                        .all(|(a, b)| (a - b).abs() <= 1e-9 * scale)
                });
                if dup {
                    continue;
                }
                seen.push(lam.clone());
                let state = self.state(&lam, alpha, &pc.classes)?;
                out.push(Solution {
                    piece: k,
                    state,
                    continuum,
                });
            }
        }
        Ok(out)
    }
}
