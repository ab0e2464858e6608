// Tests of the C++ wrapper (include/fricont.hpp) on a real problem.
//
// Usage: test_wrapper CASE_DIR REFERENCE_EVENTS
// REFERENCE_EVENTS is the output of tests-install/trace_case (the C interface used
// directly) on the same case. Prints "ok NAME" or "FAIL NAME: why" per check and exits
// with the number of failures.
#include <fricont.hpp>

#include "case.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <memory>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

static_assert(!std::is_copy_constructible<fricont::Problem>::value, "Problem is move-only");
static_assert(!std::is_copy_assignable<fricont::Problem>::value, "Problem is move-only");
static_assert(std::is_nothrow_move_constructible<fricont::Problem>::value, "noexcept move");
static_assert(std::is_nothrow_move_assignable<fricont::Problem>::value, "noexcept move");
static_assert(!std::is_copy_constructible<fricont::Path>::value, "Path is move-only");
static_assert(std::is_nothrow_move_constructible<fricont::Path>::value, "noexcept move");
static_assert(std::is_nothrow_move_assignable<fricont::Path>::value, "noexcept move");

namespace {

int failures = 0;

void report(const std::string &name, bool ok, const std::string &why = "") {
    if (ok) std::cout << "ok " << name << "\n";
    else {
        std::cout << "FAIL " << name << ": " << why << "\n";
        failures++;
    }
}

struct RefEvent {
    long index, transition, node;
    double alpha;
    std::string from, to;
    int fold, bif;
};

std::vector<RefEvent> read_reference(const std::string &path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    std::vector<RefEvent> out;
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream ss(line);
        std::string tag;
        ss >> tag;
        if (tag != "event") continue;
        RefEvent e;
        ss >> e.index >> e.transition >> e.alpha >> e.node >> e.from >> e.to >> e.fold >> e.bif;
        out.push_back(e);
    }
    return out;
}

// Compares events with the reference after mapping the reference α through `map`;
// returns an empty string or the first difference.
template <class Map>
std::string compare(const std::vector<fricont::Event> &got, const std::vector<RefEvent> &ref,
                    double rtol, Map map, std::size_t count) {
    if (got.size() < count || ref.size() < count)
        return "event counts " + std::to_string(got.size()) + " vs " + std::to_string(ref.size());
    for (std::size_t k = 0; k < count; k++) {
        const auto &g = got[k];
        const auto &r = ref[k];
        double want = map(r.alpha);
        std::ostringstream why;
        why.precision(17);
        if (g.index + 1 != r.index || g.transition + 1 != r.transition || g.node + 1 != r.node ||
            fricont::name(g.from) != r.from || fricont::name(g.to) != r.to ||
            int(g.fold) != r.fold || int(g.bifurcation) != r.bif)
            why << "event " << k + 1 << ": node " << g.node + 1 << " " << fricont::name(g.from)
                << "->" << fricont::name(g.to) << " vs node " << r.node << " " << r.from
                << "->" << r.to;
        else if (std::fabs(g.alpha - want) > rtol * std::max(1.0, std::fabs(want)))
            why << "event " << k + 1 << ": alpha " << g.alpha << " vs " << want;
        if (!why.str().empty()) return why.str();
    }
    return "";
}

// An independent check of a solution (u, λν, λt, classes) at load f: equilibrium
// A u = f + Nᵀλν + Tᵀλt, and for each node the conditions of its class (SPEC §1, §3),
// with tolerances relative to the data's scale.
std::string check_solution(const casefile::Case &c, const fricont::State &s,
                           const std::vector<double> &f) {
    const std::size_t n = c.f0.size(), p = c.gap.size();
    std::vector<double> au = c.a.apply(s.u), ntl = c.n.apply_t(s.lambda_n),
                        ttl = c.t.apply_t(s.lambda_t);
    double fscale = 0, res = 0;
    for (std::size_t i = 0; i < n; i++) {
        fscale = std::max({fscale, std::fabs(f[i]), std::fabs(au[i])});
        res = std::max(res, std::fabs(au[i] - f[i] - ntl[i] - ttl[i]));
    }
    if (res > 1e-9 * fscale) return "equilibrium residual " + std::to_string(res / fscale);
    std::vector<double> nu = c.n.apply(s.u), tu = c.t.apply(s.u);
    double lscale = 0, lam = 0;
    for (double x : s.u) lscale = std::max(lscale, std::fabs(x));
    for (std::size_t i = 0; i < p; i++)
        lam = std::max({lam, std::fabs(s.lambda_n[i]), std::fabs(s.lambda_t[i])});
    const double tl = 1e-9 * lscale, tf = 1e-9 * lam;
    for (std::size_t i = 0; i < p; i++) {
        double dn = nu[i] - c.gap[i], dt = tu[i], ln = s.lambda_n[i], lt = s.lambda_t[i];
        double fr = c.friction[i];
        bool ok = ln <= tf && dn <= tl && std::fabs(lt) <= -fr * ln + tf;
        switch (s.classes[i]) {
        case fricont::Class::Open: ok = ok && std::fabs(ln) <= tf && std::fabs(lt) <= tf; break;
        case fricont::Class::Stick: ok = ok && std::fabs(dn) <= tl && std::fabs(dt) <= tl; break;
        case fricont::Class::SlipPlus:
            ok = ok && std::fabs(dn) <= tl && std::fabs(lt - fr * ln) <= tf && dt >= -tl;
            break;
        case fricont::Class::SlipMinus:
            ok = ok && std::fabs(dn) <= tl && std::fabs(lt + fr * ln) <= tf && dt <= tl;
            break;
        }
        if (!ok)
            return "node " + std::to_string(i + 1) + " violates " + fricont::name(s.classes[i]);
    }
    return "";
}

// A banded Cholesky of the case's A (an independent solver for the host-solve tests):
// L is stored row by row over the band of half-width b.
struct BandCholesky {
    int64_t n = 0, b = 0;
    std::vector<double> l;  // l[i * (b + 1) + (i - j)] = L(i, j), i - b <= j <= i
    explicit BandCholesky(const casefile::Csr &a) : n(a.nrows) {
        for (int64_t i = 0; i < n; i++)
            for (int64_t k = a.row_ptr[i]; k < a.row_ptr[i + 1]; k++)
                b = std::max<int64_t>(b, std::llabs(i - a.col_idx[k]));
        l.assign(static_cast<std::size_t>(n * (b + 1)), 0.0);
        for (int64_t i = 0; i < n; i++)
            for (int64_t k = a.row_ptr[i]; k < a.row_ptr[i + 1]; k++) {
                int64_t j = a.col_idx[k];
                if (j <= i) at(i, j) = a.values[k];  // lower triangle (full files are symmetric)
                else if (a.symmetric) at(j, i) = a.values[k];
            }
        for (int64_t i = 0; i < n; i++)
            for (int64_t j = std::max<int64_t>(0, i - b); j <= i; j++) {
                double s = at(i, j);
                for (int64_t k = std::max<int64_t>(std::max<int64_t>(0, i - b), j - b); k < j; k++)
                    s -= at(i, k) * at(j, k);
                at(i, j) = i == j ? std::sqrt(s) : s / at(j, j);
            }
    }
    double &at(int64_t i, int64_t j) { return l[static_cast<std::size_t>(i * (b + 1) + (i - j))]; }
    void solve(double *x) {
        for (int64_t i = 0; i < n; i++) {
            double s = x[i];
            for (int64_t k = std::max<int64_t>(0, i - b); k < i; k++) s -= at(i, k) * x[k];
            x[i] = s / at(i, i);
        }
        for (int64_t i = n - 1; i >= 0; i--) {
            double s = x[i];
            for (int64_t k = i + 1; k <= std::min<int64_t>(n - 1, i + b); k++) s -= at(k, i) * x[k];
            x[i] = s / at(i, i);
        }
    }
};

std::vector<int32_t> to32(const std::vector<int64_t> &v) {
    return std::vector<int32_t>(v.begin(), v.end());
}

fricont::Problem make_problem(const casefile::Case &c) {
    fricont::CsrRef a(c.a.nrows, c.a.ncols, c.a.row_ptr, c.a.col_idx, c.a.values);
    fricont::CsrRef n(c.n.nrows, c.n.ncols, c.n.row_ptr, c.n.col_idx, c.n.values);
    fricont::CsrRef t(c.t.nrows, c.t.ncols, c.t.row_ptr, c.t.col_idx, c.t.values);
    fricont::Problem prob(a, c.a.symmetric ? fricont::Storage::Lower : fricont::Storage::Full,
                          n, t);
    prob.set_friction(c.friction);
    prob.set_gap(c.gap);
    return prob;
}

}  // namespace

int main(int argc, char **argv) {
    if (argc != 3) {
        std::cerr << "usage: test_wrapper CASE_DIR REFERENCE_EVENTS\n";
        return 2;
    }
    const casefile::Case c = casefile::read_case(argv[1]);
    const std::vector<RefEvent> ref = read_reference(argv[2]);
    const auto same = [](double a) { return a; };

    report("version matches header",
           fricont::version() == std::to_string(FRICONT_VERSION_MAJOR) + "." +
                                     std::to_string(FRICONT_VERSION_MINOR) + "." +
                                     std::to_string(FRICONT_VERSION_PATCH));

    // 1. The affine load traced through the wrapper gives the C interface's events.
    fricont::Problem prob = make_problem(c);
    report("problem dims", prob.n() == c.a.nrows && prob.p() == c.n.nrows);
    fricont::Path path = fricont::Path::affine(prob, c.f0, c.f1);
    path.set_window(c.alpha_start, c.alpha_end);
    path.start(c.alpha_start);
    fricont::EndReason why = path.run();
    std::vector<fricont::Event> ev = path.events();
    report("affine: ends at the window", why == fricont::EndReason::Window, fricont::name(why));
    report("affine: the fixed-alpha solver found the start",
           path.start_route() == fricont::StartRoute::Solved, fricont::name(path.start_route()));
    std::string diff = compare(ev, ref, 0.0, same, ref.size());
    report("affine: events equal the C reference", diff.empty() && ev.size() == ref.size(), diff);
    report("affine: pieces = events + 1", path.pieces().size() == ev.size() + 1);

    // 2. Solutions between events satisfy the equations (checked here, independently).
    if (ev.size() >= 2) {
        double alpha = 0.5 * (ev[0].alpha + ev[1].alpha);
        std::vector<fricont::Solution> sols = path.solutions_at(alpha);
        std::vector<double> f(c.f0.size());
        for (std::size_t i = 0; i < f.size(); i++) f[i] = c.f0[i] + alpha * c.f1[i];
        report("solutions_at: one solution", sols.size() == 1);
        if (!sols.empty()) {
            std::string bad = check_solution(c, sols[0].state, f);
            report("solutions_at: equilibrium and class conditions", bad.empty(), bad);
            report("solutions_at: lies on piece 1", sols[0].piece == 1);
        }
        fricont::State at = path.event_state(0);
        for (std::size_t i = 0; i < f.size(); i++) f[i] = c.f0[i] + at.alpha * c.f1[i];
        std::string bad = check_solution(c, at, f);
        report("event_state: equilibrium and class conditions", bad.empty(), bad);
    }

    // 3. Moves transfer ownership; the moved-to path keeps working.
    {
        fricont::Path moved = std::move(path);
        report("move: moved-from holds no handle", path.get() == nullptr && moved.get() != nullptr);
        fricont::Path other = fricont::Path::affine(prob, c.f0, c.f1);
        other = std::move(moved);  // frees other's first handle
        report("move: assigned path keeps its events", other.events().size() == ev.size());
        fricont::Problem p2 = std::move(prob);
        report("move: problem moved", prob.get() == nullptr && p2.get() != nullptr);
        prob = std::move(p2);
    }

    // 4. A general load f(α) = f0 + sinh(α) f1 passes the same loads: its events are at
    //    asinh of the affine ones.
    {
        auto load = [&c](double a, double *out, std::size_t n) {
            double s = std::sinh(a);
            for (std::size_t i = 0; i < n; i++) out[i] = c.f0[i] + s * c.f1[i];
        };
        auto dload = [&c](double a, double *out, std::size_t n) {
            double s = std::cosh(a);
            for (std::size_t i = 0; i < n; i++) out[i] = s * c.f1[i];
        };
        fricont::Path g = fricont::Path::general(prob, load, dload);
        g.set_window(std::asinh(c.alpha_start), std::asinh(c.alpha_end));
        g.start(std::asinh(c.alpha_start));
        fricont::EndReason r = g.run();
        std::vector<fricont::Event> gev = g.events();
        std::string d = compare(gev, ref, 1e-9, [](double a) { return std::asinh(a); }, ref.size());
        report("general load: ends at the window", r == fricont::EndReason::Window,
               fricont::name(r));
        report("general load: events at asinh(reference)",
               d.empty() && gev.size() == ref.size(), d);
    }

    //    The same as a basis load (vectors f0, f1; weights 1, sinh): the same events; an
    //    exception thrown by the weights comes back out of the call that evaluated them.
    {
        fricont::Path b = fricont::Path::basis(
            prob, {c.f0, c.f1}, [](double a, double *phi, double *dphi, std::size_t k) {
                if (k != 2) throw std::logic_error("k");
                phi[0] = 1;
                phi[1] = std::sinh(a);
                dphi[0] = 0;
                dphi[1] = std::cosh(a);
            });
        b.set_window(std::asinh(c.alpha_start), std::asinh(c.alpha_end));
        b.start(std::asinh(c.alpha_start));
        fricont::EndReason r = b.run();
        std::vector<fricont::Event> bev = b.events();
        std::string d = compare(bev, ref, 1e-9, [](double a) { return std::asinh(a); }, ref.size());
        report("basis load: events at asinh(reference)",
               r == fricont::EndReason::Window && d.empty() && bev.size() == ref.size(), d);
        fricont::Path t = fricont::Path::basis(prob, {c.f0, c.f1},
                                               [](double, double *, double *, std::size_t) {
                                                   throw std::domain_error("no weights");
                                               });
        t.set_window(c.alpha_start, c.alpha_end);
        std::string caught;
        try {
            t.start(c.alpha_start);
        } catch (const std::domain_error &e) {
            caught = e.what();
        }
        report("basis load: a throwing weights function's exception is rethrown",
               caught == "no weights", caught);
        int32_t st = 0;
        try {
            fricont::Path::basis(prob, {c.f0, {1.0}}, [](double, double *, double *, std::size_t) {});
        } catch (const fricont::Error &e) {
            st = e.status();
        }
        report("basis load: vectors of different lengths throw FRICONT_ERR_LENGTH",
               st == FRICONT_ERR_LENGTH, std::to_string(st));
    }

    // 5. An exception thrown by a load callback comes back out of the wrapper call (it
    //    never crosses the library) and the path ends, keeping what it traced.
    if (ev.size() >= 3) {
        const double stop = 0.5 * (ev[1].alpha + ev[2].alpha);
        auto load = [&c, stop](double a, double *out, std::size_t n) {
            if (a > stop) throw std::domain_error("load not defined past the stop");
            for (std::size_t i = 0; i < n; i++) out[i] = c.f0[i] + a * c.f1[i];
        };
        fricont::Path g = fricont::Path::general(prob, load);
        g.set_window(c.alpha_start, c.alpha_end);
        g.start(c.alpha_start);
        std::string caught;
        try {
            g.run();
        } catch (const std::domain_error &e) {
            caught = e.what();
        }
        report("callback exception rethrown", caught == "load not defined past the stop", caught);
        report("callback exception: path failed", g.end_reason() == fricont::EndReason::Failed);
        // The library may evaluate the load ahead of the point it reached (step control),
        // so only "a prefix of the reference events, none past the stop" is certain.
        std::vector<fricont::Event> kept = g.events();
        std::string d = compare(kept, ref, 1e-9, same, kept.size());
        report("callback exception: events kept are a prefix", d.empty() && kept.size() <= 2, d);
        bool again = false;
        try {
            g.step();
            again = true;
        } catch (...) {
        }
        report("callback exception: later step returns End", again);
    }

    // 6. Distinct paths on one problem traced from two threads at once give the same
    //    events (the handles share no mutable state).
    {
        std::vector<fricont::Event> got[2];
        std::string failure[2];
        auto work = [&](int k) {
            try {
                fricont::Path t = fricont::Path::affine(prob, c.f0, c.f1);
                t.set_window(c.alpha_start, c.alpha_end);
                t.start(c.alpha_start);
                t.run();
                got[k] = t.events();
            } catch (const std::exception &e) {
                failure[k] = e.what();
            }
        };
        std::thread t0(work, 0), t1(work, 1);
        t0.join();
        t1.join();
        std::string d0 = compare(got[0], ref, 0.0, same, ref.size());
        std::string d1 = compare(got[1], ref, 0.0, same, ref.size());
        report("two threads: both paths give the reference events",
               failure[0].empty() && failure[1].empty() && d0.empty() && d1.empty() &&
                   got[0].size() == ref.size() && got[1].size() == ref.size(),
               failure[0] + failure[1] + d0 + d1);
    }

    // 7. Errors of the library are exceptions with the status and the message.
    {
        std::vector<int64_t> ptr{0, 1, 2}, idx{0, 7};
        std::vector<double> val{1.0, 1.0};
        fricont::CsrRef bad(2, 2, ptr, idx, val);
        int32_t status = 0;
        std::string msg;
        try {
            fricont::Problem p(bad, fricont::Storage::Full, bad, bad);
        } catch (const fricont::Error &e) {
            status = e.status();
            msg = e.what();
        }
        report("bad CSR throws FRICONT_ERR_CSR", status == FRICONT_ERR_CSR, std::to_string(status));
        report("bad CSR message names the column", msg.find('7') != std::string::npos, msg);
        fricont::Path q = fricont::Path::affine(prob, c.f0, c.f1);
        status = 0;
        try {
            q.start(0.0);  // no window set
        } catch (const fricont::Error &e) {
            status = e.status();
        }
        report("start without window throws FRICONT_ERR_ORDER", status == FRICONT_ERR_ORDER);
        status = 0;
        try {
            q.start_route();
        } catch (const fricont::Error &e) {
            status = e.status();
        }
        report("start_route before the start throws FRICONT_ERR_ORDER", status == FRICONT_ERR_ORDER);
        status = 0;
        try {
            prob.set_friction(-1.0);
        } catch (const fricont::Error &e) {
            status = e.status();
        }
        report("negative friction throws FRICONT_ERR_RANGE", status == FRICONT_ERR_RANGE);
        status = 0;
        try {
            prob.set_threads(0);
        } catch (const fricont::Error &e) {
            status = e.status();
        }
        report("0 threads throws FRICONT_ERR_RANGE", status == FRICONT_ERR_RANGE);
    }

    // 8. The hosts' constructors: N, T and a solve (a banded Cholesky written here), and
    //    condensed data (W and q formed with the same solve): the C reference's events;
    //    u through the solve equals the built-in u; no u from condensed data.
    {
        auto chol = std::make_shared<BandCholesky>(c.a);
        const int64_t n = c.a.nrows, p = c.n.nrows;
        int64_t blocks = 0, widest = 0;
        auto solve = [chol, &blocks, &widest](double *x, int64_t nn, int64_t ncols, int64_t ldx) {
            blocks++;
            widest = std::max(widest, ncols);
            for (int64_t j = 0; j < ncols; j++) chol->solve(x + j * ldx);
            (void)nn;
        };
        fricont::CsrRef nr(c.n.nrows, c.n.ncols, c.n.row_ptr, c.n.col_idx, c.n.values);
        fricont::CsrRef tr(c.t.nrows, c.t.ncols, c.t.row_ptr, c.t.col_idx, c.t.values);
        fricont::Problem hosted = fricont::Problem::with_solve(n, solve, nr, tr, 8);
        hosted.set_friction(c.friction);
        hosted.set_gap(c.gap);
        fricont::Path h = fricont::Path::affine(hosted, c.f0, c.f1);
        report("host's solve: W by blocks of at most 8 columns", widest <= 8 && blocks >= (2 * p + 7) / 8,
               std::to_string(blocks) + " blocks, widest " + std::to_string(widest));
        h.set_window(c.alpha_start, c.alpha_end);
        h.start(c.alpha_start);
        report("host's solve: ends at the window", h.run() == fricont::EndReason::Window);
        std::vector<fricont::Event> hev = h.events();
        std::string d = compare(hev, ref, 1e-10, same, ref.size());
        report("host's solve: events equal the C reference", d.empty() && hev.size() == ref.size(), d);
        if (!hev.empty() && !ev.empty()) {
            fricont::State uh = h.event_state(0);
            fricont::Path own = fricont::Path::affine(prob, c.f0, c.f1);
            own.set_window(c.alpha_start, c.alpha_end);
            own.start(c.alpha_start);
            own.run();
            fricont::State uo = own.event_state(0);
            double dmax = 0, umax = 0;
            for (std::size_t i = 0; i < uo.u.size(); i++) {
                dmax = std::max(dmax, std::fabs(uo.u[i] - uh.u[i]));
                umax = std::max(umax, std::fabs(uo.u[i]));
            }
            report("host's solve: u at event 1 equals the built-in u",
                   uh.u.size() == uo.u.size() && dmax <= 1e-10 * umax, std::to_string(dmax / umax));
        }
        // condensed: W = B A^-1 B^T and q = B A^-1 f with the banded solve
        std::vector<double> w(static_cast<std::size_t>(4 * p * p)), q0(2 * p), q1(2 * p);
        auto rows = [&](const std::vector<double> &x, double *out) {
            std::vector<double> nx = c.n.apply(x), tx = c.t.apply(x);
            for (int64_t i = 0; i < p; i++) {
                out[i] = nx[i];
                out[p + i] = tx[i];
            }
        };
        for (int64_t k = 0; k < 2 * p; k++) {
            std::vector<double> e(static_cast<std::size_t>(p), 0.0);
            e[k % p] = 1.0;
            std::vector<double> x = k < p ? c.n.apply_t(e) : c.t.apply_t(e);
            chol->solve(x.data());
            rows(x, &w[static_cast<std::size_t>(k * 2 * p)]);
        }
        std::vector<double> x0 = c.f0, x1 = c.f1;
        chol->solve(x0.data());
        chol->solve(x1.data());
        rows(x0, q0.data());
        rows(x1, q1.data());
        fricont::Problem cond = fricont::Problem::condensed(p, w);
        cond.set_friction(c.friction);
        cond.set_gap(c.gap);
        report("condensed: n() is 0", cond.n() == 0 && cond.p() == p);
        fricont::Path cp = fricont::Path::affine(cond, q0, q1);
        cp.set_window(c.alpha_start, c.alpha_end);
        cp.start(c.alpha_start);
        report("condensed: ends at the window", cp.run() == fricont::EndReason::Window);
        std::vector<fricont::Event> cev = cp.events();
        d = compare(cev, ref, 1e-10, same, ref.size());
        report("condensed: events equal the C reference", d.empty() && cev.size() == ref.size(), d);
        if (!cev.empty()) {
            fricont::State cs = cp.event_state(0);
            report("condensed: states carry no u", cs.u.empty() && cs.residual <= 1e-12,
                   std::to_string(cs.residual));
        }
        // extended precision of a condensed W = diag(1/2, 1) (rows of norm 1): condition
        // 2, so auto traces in double; on, in double-double; a bad mode throws
        {
            fricont::Problem diag = fricont::Problem::condensed(1, {0.5, 0.0, 0.0, 1.0});
            diag.set_friction(0.5);
            double kappa = 0;
            bool ext = diag.extended_precision(&kappa);
            report("W = diag(1/2, 1): condition estimate 2, auto traces in double",
                   !ext && std::abs(kappa - 2) <= 1e-9, std::to_string(kappa));
            diag.set_extended_precision(fricont::ExtendedPrecision::On);
            report("extended precision on: in double-double", diag.extended_precision());
            int32_t st = 0;
            try {
                diag.set_extended_precision(static_cast<fricont::ExtendedPrecision>(3));
            } catch (const fricont::Error &e) {
                st = e.status();
            }
            report("extended precision mode 3 throws FRICONT_ERR_RANGE", st == FRICONT_ERR_RANGE,
                   std::to_string(st));
        }
        // a throwing solve is a fatal solve failure
        int32_t status = 0;
        try {
            fricont::Problem bad = fricont::Problem::with_solve(
                n, [](double *, int64_t, int64_t, int64_t) { throw std::runtime_error("no"); }, nr, tr);
            bad.build();
        } catch (const fricont::Error &e) {
            status = e.status();
        }
        report("a throwing solve gives FRICONT_ERR_SOLVE_CALLBACK", status == FRICONT_ERR_SOLVE_CALLBACK,
               std::to_string(status));

        // the host's solve with int32_t N and T: the same events
        std::vector<int32_t> np32 = to32(c.n.row_ptr), nc32 = to32(c.n.col_idx), tp32 = to32(c.t.row_ptr),
                             tc32 = to32(c.t.col_idx);
        fricont::CsrRef32 n32(c.n.nrows, c.n.ncols, np32, nc32, c.n.values);
        fricont::CsrRef32 t32(c.t.nrows, c.t.ncols, tp32, tc32, c.t.values);
        fricont::Problem hosted32 = fricont::Problem::with_solve(n, solve, n32, t32, 8);
        hosted32.set_friction(c.friction);
        hosted32.set_gap(c.gap);
        fricont::Path h32 = fricont::Path::affine(hosted32, c.f0, c.f1);
        h32.set_window(c.alpha_start, c.alpha_end);
        h32.start(c.alpha_start);
        report("host's solve, int32 N, T: ends at the window", h32.run() == fricont::EndReason::Window);
        std::vector<fricont::Event> h32ev = h32.events();
        d = compare(h32ev, ref, 1e-10, same, ref.size());
        report("host's solve, int32 N, T: events equal the C reference", d.empty() && h32ev.size() == ref.size(),
               d);
    }

    // 9. int32_t CSR (CsrRef32): the same arrays with 32-bit indices give the C reference's
    //    events bit for bit; bad 32-bit input throws the C API's status.
    {
        std::vector<int32_t> ap = to32(c.a.row_ptr), ac = to32(c.a.col_idx), np = to32(c.n.row_ptr),
                             nc = to32(c.n.col_idx), tp = to32(c.t.row_ptr), tc = to32(c.t.col_idx);
        fricont::CsrRef32 a(c.a.nrows, c.a.ncols, ap, ac, c.a.values);
        fricont::CsrRef32 n(c.n.nrows, c.n.ncols, np, nc, c.n.values);
        fricont::CsrRef32 t(c.t.nrows, c.t.ncols, static_cast<int64_t>(tc.size()), tp.data(), tc.data(),
                            c.t.values.data());
        fricont::Problem p32(a, c.a.symmetric ? fricont::Storage::Lower : fricont::Storage::Full, n, t);
        p32.set_friction(c.friction);
        p32.set_gap(c.gap);
        fricont::Path q = fricont::Path::affine(p32, c.f0, c.f1);
        q.set_window(c.alpha_start, c.alpha_end);
        q.start(c.alpha_start);
        report("int32 CSR: ends at the window", q.run() == fricont::EndReason::Window);
        std::vector<fricont::Event> qev = q.events();
        std::string d = compare(qev, ref, 0.0, same, ref.size());
        report("int32 CSR: events equal the C reference", d.empty() && qev.size() == ref.size(), d);
        const std::pair<std::vector<int32_t>, std::vector<int32_t>> bad[3] = {
            {{0, 1, 2}, {0, -1}}, {{0, 2, 1}, {0, 1}}, {{0, 1, 2}, {0, 2}}};
        const char *what[3] = {"a negative column", "a decreasing row pointer", "a column out of range"};
        std::vector<double> val{1.0, 1.0};
        for (int k = 0; k < 3; k++) {
            fricont::CsrRef32 b(2, 2, bad[k].first, bad[k].second, val);
            int32_t status = 0;
            try {
                fricont::Problem pb(b, fricont::Storage::Full, b, b);
            } catch (const fricont::Error &e) {
                status = e.status();
            }
            report(std::string("int32 CSR with ") + what[k] + " throws FRICONT_ERR_CSR", status == FRICONT_ERR_CSR,
                   std::to_string(status));
        }
    }

    // 9. The monitor (reference: the C interface's events of the same path, unmonitored):
    //    stopping after the third transition point keeps exactly the reference's first
    //    events, and running again ends where the reference ends, with its events; the
    //    monitor reads the path from inside the call.
    {
        long ref_transitions = ref.empty() ? 0 : ref.back().transition;
        struct Seen {
            double alpha;
            int64_t transitions, first, end, events_inside;
        };
        std::vector<Seen> seen;
        fricont::Path m = fricont::Path::affine(prob, c.f0, c.f1);
        m.set_window(c.alpha_start, c.alpha_end);
        m.set_monitor([&seen, &m](double a, int64_t tr, int64_t first, int64_t end) {
            seen.push_back({a, tr, first, end, static_cast<int64_t>(m.events().size())});
            return tr == 3;
        });
        m.start(c.alpha_start);
        fricont::EndReason r = m.run();
        report("monitor: stop after 3 transition points ends with Stopped",
               r == fricont::EndReason::Stopped && m.end_reason() == fricont::EndReason::Stopped &&
                   fricont::name(r) == "stopped",
               fricont::name(r));
        bool args_ok = seen.size() == 3 && ref_transitions >= 4;
        for (std::size_t k = 0; args_ok && k < seen.size(); k++) {
            const Seen &s = seen[k];
            args_ok = s.transitions == static_cast<int64_t>(k + 1) &&
                      s.first == (k ? seen[k - 1].end : 0) && s.end > s.first &&
                      s.events_inside == s.end && s.end <= static_cast<int64_t>(ref.size()) &&
                      s.alpha == ref[static_cast<std::size_t>(s.first)].alpha &&
                      ref[static_cast<std::size_t>(s.end - 1)].transition == s.transitions;
        }
        report("monitor: alpha, transition count and new events of each call", args_ok,
               std::to_string(seen.size()) + " calls");
        std::vector<fricont::Event> got = m.events();
        std::string d = seen.size() == 3 ? compare(got, ref, 0.0, same, got.size()) : "no stop";
        report("monitor: events at the stop are the reference's first ones",
               d.empty() && seen.size() == 3 && got.size() == static_cast<std::size_t>(seen[2].end),
               d);
        r = m.run();
        got = m.events();
        d = compare(got, ref, 0.0, same, ref.size());
        report("monitor: running again ends at the window with the reference's events",
               r == fricont::EndReason::Window && d.empty() && got.size() == ref.size() &&
                   static_cast<long>(seen.size()) == ref_transitions,
               fricont::name(r) + " " + d);
    }

    // 10. An exception thrown by the monitor comes out of run() (never crossing the
    //     library), the path is stopped where it was, and it stays usable.
    {
        fricont::Path x = fricont::Path::affine(prob, c.f0, c.f1);
        x.set_window(c.alpha_start, c.alpha_end);
        x.set_monitor([](double, int64_t tr, int64_t, int64_t) -> bool {
            if (tr == 2) throw std::out_of_range("the monitor gave up at 2");
            return false;
        });
        x.start(c.alpha_start);
        std::string caught;
        try {
            x.run();
        } catch (const std::out_of_range &e) {
            caught = e.what();
        }
        report("monitor exception rethrown by run()", caught == "the monitor gave up at 2", caught);
        std::size_t upto = 0;
        while (upto < ref.size() && ref[upto].transition <= 2) upto++;
        std::vector<fricont::Event> got = x.events();
        std::string d = compare(got, ref, 0.0, same, got.size());
        report("monitor exception: stopped after transition point 2, events kept",
               x.end_reason() == fricont::EndReason::Stopped && d.empty() && got.size() == upto,
               fricont::name(x.end_reason()) + " " + d);
        x.set_monitor(nullptr);
        fricont::EndReason r = x.run();
        got = x.events();
        d = compare(got, ref, 0.0, same, ref.size());
        report("monitor exception: the path runs on to the reference's end",
               r == fricont::EndReason::Window && d.empty() && got.size() == ref.size(), d);
    }

    // 11. The largest alpha step: range and order errors; a narrow bump of a general load
    //     (tests/core_oscillating.rs): one node, A = I, N = [1 0], T = [0 1], normal load
    //     0.5 - 0.6 exp(-((a - a_b)/w)^2) opens the node where the exponential exceeds 5/6,
    //     i.e. between a_b -+ w sqrt(ln 1.2); the default steps step over it, steps of at
    //     most 1e-3 find both transitions there.
    {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        const double inf = std::numeric_limits<double>::infinity();
        fricont::Path g = fricont::Path::affine(prob, c.f0, c.f1);
        g.set_window(c.alpha_start, c.alpha_end);
        bool all_range = true;
        for (double h : {0.0, -1.0, nan, inf}) {
            int32_t status = 0;
            try {
                g.set_max_alpha_step(h);
            } catch (const fricont::Error &e) {
                status = e.status();
            }
            all_range = all_range && status == FRICONT_ERR_RANGE;
        }
        report("max_alpha_step 0, -1, NaN, inf: FRICONT_ERR_RANGE", all_range);
        g.set_max_alpha_step(0.1);
        g.start(c.alpha_start);
        int32_t status = 0;
        try {
            g.set_max_alpha_step(0.1);
        } catch (const fricont::Error &e) {
            status = e.status();
        }
        report("max_alpha_step after the start: FRICONT_ERR_ORDER", status == FRICONT_ERR_ORDER);

        std::vector<int64_t> aptr{0, 1, 2}, aidx{0, 1}, ptr{0, 1}, nidx{0}, tidx{1};
        std::vector<double> aval{1.0, 1.0}, one{1.0};
        fricont::Problem node(fricont::CsrRef(2, 2, aptr, aidx, aval), fricont::Storage::Full,
                              fricont::CsrRef(1, 2, ptr, nidx, one),
                              fricont::CsrRef(1, 2, ptr, tidx, one));
        node.set_friction(0.3);
        const double ab = 21.5 / 64.0, w = 2e-3;
        fricont::Path bump = fricont::Path::general(node, [ab, w](double a, double *out, std::size_t) {
            out[0] = 0.5 - 0.6 * std::exp(-std::pow((a - ab) / w, 2));
            out[1] = 0.0;
        });
        bump.set_window(-1.0, 1.0);
        bump.set_max_alpha_step(1e-3);
        bump.start(-1.0);
        fricont::EndReason r = bump.run();
        std::vector<fricont::Event> be = bump.events();
        const double half = w * std::sqrt(std::log(1.2));
        bool found = r == fricont::EndReason::Window && be.size() == 2;
        std::ostringstream why;
        why.precision(17);
        why << be.size() << " events";
        if (found) {
            why << " at " << be[0].alpha << ", " << be[1].alpha;
            found = std::fabs(be[0].alpha - (ab - half)) <= 1e-10 &&
                    std::fabs(be[1].alpha - (ab + half)) <= 1e-10 &&
                    be[0].from == fricont::Class::Stick && be[0].to == fricont::Class::Open &&
                    be[1].from == fricont::Class::Open && be[1].to == fricont::Class::Stick;
        }
        report("max_alpha_step 1e-3: both transitions of a narrow bump at the analytic alpha",
               found, why.str());
    }

    std::cout << "cpp-tests: " << failures << " failed check(s)\n";
    return failures;
}
