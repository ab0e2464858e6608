// fricont.hpp: a header-only C++17 wrapper over the C interface (fricont.h).
//
// * `fricont::Problem` and `fricont::Path` own their handles: the destructor frees them;
//   they are move-only (no copies, a moved-from object holds no handle).
// * Every failing C call becomes a `fricont::Error` (status code and the library's
//   message), thrown here, on the C++ side, after the C call has returned.
// * A load given as a C++ callable is called through a `noexcept` trampoline: an
//   exception it throws is caught before it could reach the library, the callback returns
//   a nonzero code (the library ends the step cleanly), and the wrapper rethrows the
//   original exception once the C call has returned. A progress monitor
//   (`Path::set_monitor`) is wrapped the same way: an exception it throws stops the path
//   (`EndReason::Stopped`) and is rethrown by `Path::run`.
// * Indices are those of the C interface: 0-based nodes, events and pieces; CSR input
//   (`CsrRef` with int64_t indices, `CsrRef32` with int32_t ones) takes an `index_base`
//   of 0 or 1, and sums duplicate entries.
//
// Link as for the C interface (`pkg-config --cflags --libs fricont`, or CMake
// `find_package(fricont)` and `target_link_libraries(app fricont::fricont)`).
#ifndef FRICONT_HPP
#define FRICONT_HPP

#include <fricont.h>

#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace fricont {

/// A failed call: `status()` is the `fricont_status` code (negative), `what()` the
/// library's message ("FRICONT_ERR_CSR: A (CSR): row 17 ...").
class Error : public std::runtime_error {
public:
    Error(int32_t status, const std::string &message)
        : std::runtime_error(message), status_(status) {}
    /// The negative `fricont_status` code of the failing call.
    int32_t status() const noexcept { return status_; }

private:
    int32_t status_;
};

/// Class of a contact node (SPEC §3).
enum class Class : int32_t {
    Open = FRICONT_OPEN,
    Stick = FRICONT_STICK,
    SlipPlus = FRICONT_SLIP_PLUS,
    SlipMinus = FRICONT_SLIP_MINUS,
};

/// "open", "stick", "slip+" or "slip-".
inline std::string name(Class c) { return fricont_class_name(static_cast<int32_t>(c)); }

/// Which triangle of A is passed.
enum class Storage : int32_t {
    Full = FRICONT_STORAGE_FULL,
    Lower = FRICONT_STORAGE_LOWER,
    Upper = FRICONT_STORAGE_UPPER,
};

/// Whether W and the condensed loads are carried beyond double precision (see
/// `fricont_problem_set_extended_precision`).
enum class ExtendedPrecision : int32_t {
    /// Where the refinement is cheap, or W is ill-conditioned and it is affordable.
    Auto = 0,
    On = 1,
    Off = 2,
};

/// What a step found (the positive outcomes of `fricont_path_step`).
enum class Outcome : int32_t {
    Transition = FRICONT_TRANSITION,
    Fold = FRICONT_FOLD,
    Bifurcation = FRICONT_BIFURCATION,
    End = FRICONT_END,
};

/// Why a path ended.
enum class EndReason : int32_t {
    None = FRICONT_END_NONE,
    Window = FRICONT_END_WINDOW,
    MaxSteps = FRICONT_END_MAX_STEPS,
    ClosedLoop = FRICONT_END_CLOSED_LOOP,
    Bifurcation = FRICONT_END_BIFURCATION,
    Failed = FRICONT_END_FAILED,
    /// The monitor (`Path::set_monitor`) stopped the path; `run`/`step` continue from there.
    Stopped = FRICONT_END_STOPPED,
};

/// "none", "window", "max_steps", "closed_loop", "bifurcation", "failed" or "stopped"
/// (`fricont_end_reason_name`).
inline std::string name(EndReason r) {
    return fricont_end_reason_name(static_cast<int32_t>(r));
}

/// How `Path::start` reached the start point (`Path::start_route`): the fixed-α solver,
/// or one of its fallbacks where the solver failed (see `fricont_path_start`).
enum class StartRoute : int32_t {
    Solved = FRICONT_START_SOLVED,
    Nearby = FRICONT_START_NEARBY,
    ZeroLoad = FRICONT_START_ZERO_LOAD,
    Open = FRICONT_START_OPEN,
};

/// "solved", "nearby", "zero_load" or "open" (`fricont_start_route_name`).
inline std::string name(StartRoute r) {
    return fricont_start_route_name(static_cast<int32_t>(r));
}

/// The library's run-time version "MAJOR.MINOR.PATCH".
inline std::string version() { return fricont_version(); }

namespace detail {
/// The C struct of a CSR view with `Index` indices.
template <class Index> struct CsrC;
template <> struct CsrC<int64_t> { using type = fricont_csr; };
template <> struct CsrC<int32_t> { using type = fricont_csr_i32; };
}  // namespace detail

/// A borrowed CSR matrix with `int64_t` (`CsrRef`) or `int32_t` (`CsrRef32`) indices: the
/// caller's arrays, read (and copied by the library) only during the call that receives
/// it, so 32-bit index arrays are used as they are, without a copy on the caller's side.
/// Columns may be unsorted and may repeat within a row (duplicates are summed).
template <class Index> struct BasicCsrRef {
    static_assert(std::is_same<Index, int64_t>::value || std::is_same<Index, int32_t>::value,
                  "fricont CSR indices are int64_t or int32_t");
    int64_t nrows = 0;
    int64_t ncols = 0;
    const Index *row_ptr = nullptr;  ///< nrows + 1 entries
    const Index *col_idx = nullptr;  ///< nnz entries
    const double *values = nullptr;  ///< nnz entries
    int64_t index_base = 0;          ///< 0 or 1

    BasicCsrRef() = default;
    /// From vectors (nnz = col_idx.size()).
    BasicCsrRef(int64_t rows, int64_t cols, const std::vector<Index> &ptr,
                const std::vector<Index> &idx, const std::vector<double> &vals,
                int64_t base = 0)
        : nrows(rows), ncols(cols), row_ptr(ptr.data()), col_idx(idx.data()),
          values(vals.data()), index_base(base), nnz_(static_cast<int64_t>(idx.size())) {}
    /// From raw arrays of `nnz` entries.
    BasicCsrRef(int64_t rows, int64_t cols, int64_t nnz, const Index *ptr, const Index *idx,
                const double *vals, int64_t base = 0)
        : nrows(rows), ncols(cols), row_ptr(ptr), col_idx(idx), values(vals),
          index_base(base), nnz_(nnz) {}

    /// The C view (`fricont_csr` or `fricont_csr_i32`).
    typename detail::CsrC<Index>::type c() const {
        return {nrows, ncols, nnz_, row_ptr, col_idx, values, index_base};
    }

private:
    int64_t nnz_ = 0;
};

/// CSR with `int64_t` indices (`fricont_csr`).
using CsrRef = BasicCsrRef<int64_t>;
/// CSR with `int32_t` indices (`fricont_csr_i32`): PETSc's default, Eigen, CHOLMOD's int
/// API, scipy.
using CsrRef32 = BasicCsrRef<int32_t>;

/// One node changing class (C++ copy of `fricont_event`; 0-based index, node).
struct Event {
    int64_t index = 0;
    int64_t transition = 0;
    double alpha = 0.0;
    int64_t node = 0;
    Class from = Class::Open;
    Class to = Class::Open;
    bool fold = false;
    bool bifurcation = false;
    double residual = 0.0;
};

/// A point of the solution curve (u: n values; lambda_n, lambda_t, classes: p values).
struct State {
    double alpha = 0.0;
    double residual = 0.0;
    std::vector<double> u;
    std::vector<double> lambda_n;
    std::vector<double> lambda_t;
    std::vector<Class> classes;
};

/// A traced smooth piece.
struct Piece {
    double alpha_from = 0.0;
    double alpha_to = 0.0;
    int32_t direction = 0;
    int32_t orientation = 0;
    int32_t det_sign = 0;
    std::vector<Class> classes;
};

/// A candidate continuation at a bifurcation.
struct Branch {
    int32_t direction = 0;
    bool orientation_preserving = false;
    std::vector<Class> classes;
};

/// A solution at a given α (see `Path::solutions_at`).
struct Solution {
    int64_t piece = 0;
    bool continuum = false;
    State state;
};

namespace detail {

inline std::string last_error() {
    std::string s(fricont_last_error_message(nullptr, 0), '\0');
    if (!s.empty()) fricont_last_error_message(&s[0], s.size() + 1);
    return s;
}

inline std::string status_text(int32_t st) { return fricont_status_str(st); }

/// Throws `Error` for a negative status (with the thread's last error message).
inline int32_t check(int32_t st) {
    if (st < 0) throw Error(st, last_error());
    return st;
}

inline std::vector<Class> to_classes(const std::vector<int32_t> &codes) {
    std::vector<Class> out;
    out.reserve(codes.size());
    for (int32_t c : codes) out.push_back(static_cast<Class>(c));
    return out;
}

/// Callback context owned by the library (freed through `fricont_cxx_free_context`).
struct LoadContext {
    std::function<void(double, double *, std::size_t)> f;
    std::function<void(double, double *, std::size_t)> df;
    std::exception_ptr pending;
    /// A basis load's weights (f and df empty then).
    std::function<void(double, double *, double *, std::size_t)> w;
};

/// Runs a load or weights callable: 0, or 1 with its exception kept in `ctx`.
template <class Call> int32_t guarded(LoadContext *ctx, Call &&call) noexcept {
    try {
        call();
        return 0;
    } catch (...) {
        // Never let an exception reach the library: keep it and return a code.
        if (!ctx->pending) ctx->pending = std::current_exception();
        return 1;
    }
}

extern "C" inline int32_t fricont_cxx_load_trampoline(double alpha, double *out, int64_t n,
                                                      void *ud) {
    auto *ctx = static_cast<LoadContext *>(ud);
    return guarded(ctx, [&] { ctx->f(alpha, out, static_cast<std::size_t>(n)); });
}

extern "C" inline int32_t fricont_cxx_dload_trampoline(double alpha, double *out, int64_t n,
                                                       void *ud) {
    auto *ctx = static_cast<LoadContext *>(ud);
    return guarded(ctx, [&] { ctx->df(alpha, out, static_cast<std::size_t>(n)); });
}

extern "C" inline int32_t fricont_cxx_weights_trampoline(double alpha, double *phi,
                                                         double *dphi, int64_t k, void *ud) {
    auto *ctx = static_cast<LoadContext *>(ud);
    return guarded(ctx, [&] { ctx->w(alpha, phi, dphi, static_cast<std::size_t>(k)); });
}

extern "C" inline void fricont_cxx_free_context(void *ud) {
    delete static_cast<LoadContext *>(ud);
}

/// A monitor's context, owned by the library (freed through `fricont_cxx_free_monitor`
/// when the monitor is replaced or removed, or the path freed). `pending` is shared with
/// the `Path`, so that an exception is kept even if the monitor replaced itself.
struct MonitorContext {
    std::function<bool(double, int64_t, int64_t, int64_t)> f;
    std::shared_ptr<std::exception_ptr> pending;
};

extern "C" inline int32_t fricont_cxx_monitor_trampoline(double alpha, int64_t transitions,
                                                         int64_t first_event, int64_t end_event,
                                                         void *ud) {
    auto *ctx = static_cast<MonitorContext *>(ud);
    try {
        return ctx->f(alpha, transitions, first_event, end_event) ? 1 : 0;
    } catch (...) {
        // Never let an exception reach the library: keep it and stop the path.
        if (!*ctx->pending) *ctx->pending = std::current_exception();
        return 1;
    }
}

extern "C" inline void fricont_cxx_free_monitor(void *ud) {
    delete static_cast<MonitorContext *>(ud);
}

}  // namespace detail

/// A contact problem (A, N, T, friction, gap, r). Move-only; the destructor frees it.
class Problem {
public:
    /// Copies A (symmetric positive definite, in `storage`), N and T (p×n). Throws
    /// `Error` on malformed or non-finite input (see `fricont_problem_new`).
    Problem(const CsrRef &a, Storage storage, const CsrRef &n, const CsrRef &t) {
        fricont_csr ca = a.c(), cn = n.c(), ct = t.c();
        detail::check(fricont_problem_new(&ca, static_cast<int32_t>(storage), &cn, &ct, &h_));
    }
    /// The same with int32_t indices (see `fricont_problem_new_i32`).
    Problem(const CsrRef32 &a, Storage storage, const CsrRef32 &n, const CsrRef32 &t) {
        fricont_csr_i32 ca = a.c(), cn = n.c(), ct = t.c();
        detail::check(
            fricont_problem_new_i32(&ca, static_cast<int32_t>(storage), &cn, &ct, &h_));
    }
    /// From condensed data (see `fricont_problem_new_condensed`): W = B A⁻¹ Bᵀ, 2p × 2p,
    /// column-major (`w.size() == 4p²`), symmetric positive definite. Loads are then
    /// condensed vectors of 2p entries; states carry no u (`State::u` stays empty) and
    /// `n()` is 0. Throws `Error` (checks of W happen at the first build).
    static Problem condensed(int64_t p, const std::vector<double> &w) {
        if (p < 1 || w.size() != static_cast<std::size_t>(4 * p * p))
            throw Error(FRICONT_ERR_LENGTH,
                        "fricont::Problem::condensed: W must hold 2p x 2p values, p >= 1");
        Problem prob;
        detail::check(fricont_problem_new_condensed(p, w.data(), 2 * p, &prob.h_));
        return prob;
    }

    /// The host's solve: overwrite the `ncols` columns of `x` (n rows, column-major,
    /// leading dimension `ldx`) with A⁻¹ times them. An exception it throws becomes a
    /// fatal failure (`FRICONT_ERR_SOLVE_CALLBACK`, code −1) of the fricont call in which
    /// it ran.
    using SolveFn = std::function<void(double *x, int64_t n, int64_t ncols, int64_t ldx)>;

    /// From N, T (p × n) and the host's own solve with A (see `fricont_problem_new_solve`):
    /// W is formed by 2p solves in blocks of at most `max_block` columns. The solve is
    /// kept (copied) until the problem and every path made from it are gone.
    static Problem with_solve(int64_t n, SolveFn solve, const CsrRef &nm, const CsrRef &t,
                              int64_t max_block = 64) {
        if (!solve) throw Error(FRICONT_ERR_NULL, "fricont::Problem::with_solve: no solve");
        auto *ctx = new SolveFn(std::move(solve));
        fricont_csr cn = nm.c(), ct = t.c();
        Problem prob;
        // The library owns ctx from here: it calls the finalizer (also on failure).
        detail::check(fricont_problem_new_solve(n, &Problem::solve_trampoline, ctx,
                                                &Problem::solve_free, max_block, &cn, &ct,
                                                &prob.h_));
        return prob;
    }
    /// The same with int32_t indices in N and T (see `fricont_problem_new_solve_i32`).
    static Problem with_solve(int64_t n, SolveFn solve, const CsrRef32 &nm, const CsrRef32 &t,
                              int64_t max_block = 64) {
        if (!solve) throw Error(FRICONT_ERR_NULL, "fricont::Problem::with_solve: no solve");
        auto *ctx = new SolveFn(std::move(solve));
        fricont_csr_i32 cn = nm.c(), ct = t.c();
        Problem prob;
        // The library owns ctx from here: it calls the finalizer (also on failure).
        detail::check(fricont_problem_new_solve_i32(n, &Problem::solve_trampoline, ctx,
                                                    &Problem::solve_free, max_block, &cn, &ct,
                                                    &prob.h_));
        return prob;
    }

    Problem(const Problem &) = delete;
    Problem &operator=(const Problem &) = delete;
    Problem(Problem &&o) noexcept : h_(std::exchange(o.h_, nullptr)) {}
    Problem &operator=(Problem &&o) noexcept {
        if (this != &o) {
            fricont_problem_free(h_);
            h_ = std::exchange(o.h_, nullptr);
        }
        return *this;
    }
    ~Problem() { fricont_problem_free(h_); }

    /// The same friction coefficient F ≥ 0 at every node.
    void set_friction(double f) { check(fricont_problem_set_friction(h_, f)); }
    /// One friction coefficient per node (p values).
    void set_friction(const std::vector<double> &f) {
        check(fricont_problem_set_friction_nodes(h_, f.data(),
                                                 static_cast<int64_t>(f.size())));
    }
    /// The initial normal gap g (p values, length units).
    void set_gap(const std::vector<double> &g) {
        check(fricont_problem_set_gap(h_, g.data(), static_cast<int64_t>(g.size())));
    }
    /// The augmentation parameter r > 0 (does not change solutions).
    void set_r(double r) { check(fricont_problem_set_r(h_, r)); }
    /// Threads of the set-up (factorisation of A, forming W) and, where 2p ≥ 2048, of the
    /// trace's dense passes (a private pool per call into a path), 1..=1024; default 1
    /// (no thread started). Results agree with one thread to rounding. Throws on a bad
    /// count.
    void set_threads(int64_t threads) { check(fricont_problem_set_threads(h_, threads)); }
    /// Extended precision (default `Auto`; see `fricont_problem_set_extended_precision`):
    /// a change drops the factorisation, the next build factorises again.
    void set_extended_precision(ExtendedPrecision mode) {
        check(fricont_problem_set_extended_precision(h_, static_cast<int32_t>(mode)));
    }
    /// Whether the problem is traced in extended precision (builds it if needed; throws
    /// the build's errors); `*w_condition`, when not null, receives the estimate of the
    /// 2-norm condition number of the equilibrated W (dimensionless).
    bool extended_precision(double *w_condition = nullptr) {
        int32_t e = 0;
        check(fricont_problem_extended_precision(h_, &e, w_condition));
        return e != 0;
    }
    /// Validates and factorises now (optional).
    void build() { check(fricont_problem_build(h_)); }
    /// Number of dofs n.
    int64_t n() const {
        int64_t n = 0;
        check(fricont_problem_dims(h_, &n, nullptr));
        return n;
    }
    /// Number of contact nodes p.
    int64_t p() const {
        int64_t p = 0;
        check(fricont_problem_dims(h_, nullptr, &p));
        return p;
    }
    /// The augmentation parameter in use (builds if needed).
    double r() {
        double r = 0.0;
        check(fricont_problem_r(h_, &r, nullptr));
        return r;
    }
    /// Its data-derived default 2p / trace(W).
    double default_r() {
        double r = 0.0;
        check(fricont_problem_r(h_, nullptr, &r));
        return r;
    }
    /// The C handle (still owned by this object).
    fricont_problem *get() const noexcept { return h_; }

private:
    Problem() = default;
    static int solve_trampoline(void *user, int64_t n, int64_t ncols, double *x, int64_t ldx) {
        try {
            (*static_cast<SolveFn *>(user))(x, n, ncols, ldx);
            return 0;
        } catch (...) {
            return -1;
        }
    }
    static void solve_free(void *user) { delete static_cast<SolveFn *>(user); }

    int32_t check(int32_t st) const {
        if (st < 0) {
            std::string msg(fricont_problem_error_message(h_, nullptr, 0), '\0');
            if (!msg.empty()) fricont_problem_error_message(h_, &msg[0], msg.size() + 1);
            else msg = detail::last_error();
            throw Error(st, msg);
        }
        return st;
    }
    fricont_problem *h_ = nullptr;
};

/// A load path on a problem, traced step by step. Move-only; the destructor frees it.
class Path {
public:
    /// A load callback: writes f(α) (or f'(α)) into `out[0..n)`. It may throw: the
    /// exception is rethrown by the `Path` call during which it was raised.
    using LoadFn = std::function<void(double alpha, double *out, std::size_t n)>;

    /// The affine load f(α) = f0 + α f1 (n values each).
    static Path affine(Problem &problem, const std::vector<double> &f0,
                       const std::vector<double> &f1) {
        if (f0.size() != f1.size())
            throw Error(FRICONT_ERR_LENGTH, "fricont::Path::affine: f0 and f1 differ in length");
        Path path(problem);
        detail::check(fricont_path_new_affine(problem.get(), f0.data(), f1.data(),
                                              static_cast<int64_t>(f0.size()), &path.h_));
        return path;
    }

    /// The weights of a basis load: writes φ_j(α) into `phi[0..k)` and φ_j'(α) into
    /// `dphi[0..k)`. It may throw, as a `LoadFn`.
    using WeightsFn = std::function<void(double alpha, double *phi, double *dphi, std::size_t k)>;

    /// The basis load f(α) = Σ_j φ_j(α) f_j: `vectors` the k fixed vectors f_j (n values
    /// each, copied), `weights` their weights. Each vector is condensed once, so that an
    /// evaluation costs O(k p) where a `general` load costs a solve with the piece matrix
    /// (and with A, until its evaluations span the load's directions): prefer it
    /// whenever the load is a combination of fixed vectors. Throws for no vectors,
    /// vectors of different lengths, an empty `weights`, and the library's errors.
    static Path basis(Problem &problem, const std::vector<std::vector<double>> &vectors,
                      WeightsFn weights) {
        if (!weights) throw Error(FRICONT_ERR_NULL, "fricont::Path::basis: empty weights function");
        if (vectors.empty()) throw Error(FRICONT_ERR_LENGTH, "fricont::Path::basis: no vectors");
        std::vector<double> flat;
        flat.reserve(vectors.size() * vectors[0].size());
        for (const auto &v : vectors) {
            if (v.size() != vectors[0].size())
                throw Error(FRICONT_ERR_LENGTH, "fricont::Path::basis: vectors differ in length");
            flat.insert(flat.end(), v.begin(), v.end());
        }
        Path path(problem);
        auto *ctx = new detail::LoadContext{nullptr, nullptr, nullptr, std::move(weights)};
        path.ctx_ = ctx;
        // The library owns ctx from here (freed exactly once, also when creation fails).
        int32_t st = fricont_path_new_basis(
            problem.get(), flat.data(), static_cast<int64_t>(vectors[0].size()),
            static_cast<int64_t>(vectors.size()), detail::fricont_cxx_weights_trampoline, ctx,
            detail::fricont_cxx_free_context, &path.h_);
        if (st < 0) {
            path.ctx_ = nullptr;
            detail::check(st);
        }
        return path;
    }

    /// A general load f(α) from a callable, with an optional derivative f'(α).
    static Path general(Problem &problem, LoadFn f, LoadFn df = nullptr) {
        if (!f) throw Error(FRICONT_ERR_NULL, "fricont::Path::general: empty load function");
        Path path(problem);
        auto *ctx = new detail::LoadContext{std::move(f), std::move(df), nullptr, nullptr};
        path.ctx_ = ctx;
        // The library owns ctx from here: it calls fricont_cxx_free_context exactly once
        // (also when the creation fails).
        int32_t st = fricont_path_new_general(
            problem.get(), path.n_, detail::fricont_cxx_load_trampoline,
            ctx->df ? detail::fricont_cxx_dload_trampoline : nullptr, ctx,
            detail::fricont_cxx_free_context, &path.h_);
        if (st < 0) {
            path.ctx_ = nullptr;
            detail::check(st);
        }
        return path;
    }

    Path(const Path &) = delete;
    Path &operator=(const Path &) = delete;
    Path(Path &&o) noexcept
        : h_(std::exchange(o.h_, nullptr)), ctx_(std::exchange(o.ctx_, nullptr)),
          pending_(std::move(o.pending_)), n_(o.n_), p_(o.p_) {}
    Path &operator=(Path &&o) noexcept {
        if (this != &o) {
            fricont_path_free(h_);
            h_ = std::exchange(o.h_, nullptr);
            ctx_ = std::exchange(o.ctx_, nullptr);
            pending_ = std::move(o.pending_);
            n_ = o.n_;
            p_ = o.p_;
        }
        return *this;
    }
    ~Path() { fricont_path_free(h_); }

    /// Number of dofs n and contact nodes p of the problem.
    int64_t n() const noexcept { return n_; }
    int64_t p() const noexcept { return p_; }

    /// The α window (required before `start`).
    void set_window(double alpha_start, double alpha_end) {
        check(fricont_path_set_window(h_, alpha_start, alpha_end));
    }
    /// The step limit (default 10000).
    void set_max_steps(int64_t max_steps) { check(fricont_path_set_max_steps(h_, max_steps)); }
    /// The relative zero tolerance of guards (default 1e-11).
    void set_zero_tol(double tol) { check(fricont_path_set_zero_tol(h_, tol)); }
    /// The largest α step (α units) of the step control of a nonlinear load (`general`):
    /// default 1/8 of the window. A load feature narrower than the steps (a bump, a fast
    /// oscillation) can be stepped over; a largest step no longer than the narrowest
    /// feature cannot miss it (see `fricont_path_set_max_alpha_step`). No effect on an
    /// affine load. Before `start` only. Throws `Error` (FRICONT_ERR_RANGE when not finite
    /// or <= 0, FRICONT_ERR_ORDER after the start).
    void set_max_alpha_step(double h) { check(fricont_path_set_max_alpha_step(h_, h)); }

    /// A progress monitor: `monitor(alpha, transitions, first_event, end_event)` is called
    /// by `run` after each transition point, with its α, the number of transition points
    /// traced so far and the new events `first_event .. end_event - 1` (0-based indices
    /// into `events()`). Return `false` to go on, `true` to stop: `run` then returns
    /// `EndReason::Stopped`, keeping everything traced, and the next `run` or `step`
    /// continues from there. An exception the monitor throws also stops the path and is
    /// rethrown by `run` (never crossing the library); the path stays usable.
    using MonitorFn = std::function<bool(double alpha, int64_t transitions, int64_t first_event,
                                         int64_t end_event)>;

    /// Sets the monitor (replacing any earlier one), or removes it when `monitor` is empty.
    /// It may read this path (`events()`, `event_state`, ...) from inside the call; it must
    /// not destroy or move it. Called by `run` only, not by `step`.
    void set_monitor(MonitorFn monitor) {
        if (!monitor) {
            check(fricont_path_set_monitor(h_, nullptr, nullptr, nullptr));
            return;
        }
        if (!pending_) pending_ = std::make_shared<std::exception_ptr>();
        auto *ctx = new detail::MonitorContext{std::move(monitor), pending_};
        // The library owns ctx from here: it calls fricont_cxx_free_monitor exactly once
        // (also when this call fails).
        check(fricont_path_set_monitor(h_, detail::fricont_cxx_monitor_trampoline, ctx,
                                       detail::fricont_cxx_free_monitor));
    }

    /// Starts at α from zero contact forces, or from `guess` = (λν, λt) (2p values).
    void start(double alpha, const std::vector<double> &guess = {}) {
        check(fricont_path_start(h_, alpha, guess.empty() ? nullptr : guess.data(),
                                 static_cast<int64_t>(guess.size())));
    }
    /// Advances to the next transition point or to the end.
    Outcome step() { return static_cast<Outcome>(check(fricont_path_step(h_))); }
    /// Steps until the end, calling the monitor (if set) after each transition point;
    /// returns why it ended (`EndReason::Stopped` when the monitor asked to stop).
    /// Rethrows an exception of a load callback or of the monitor.
    EndReason run() {
        check(fricont_path_run(h_));
        return end_reason();
    }
    /// Why the path ended (`EndReason::None` while it goes on).
    EndReason end_reason() const {
        int32_t r = 0;
        check(fricont_path_end_reason(h_, &r));
        return static_cast<EndReason>(r);
    }
    /// How the start point was reached (`StartRoute::Solved` unless a fallback of the
    /// fixed-α solver found it). Throws `fricont::Error` (`FRICONT_ERR_ORDER`) before the start.
    StartRoute start_route() const {
        int32_t r = 0;
        check(fricont_path_start_route(h_, &r));
        return static_cast<StartRoute>(r);
    }
    /// The code of the last failing load callback (0 if none).
    int32_t callback_code() const {
        int32_t c = 0;
        check(fricont_path_callback_code(h_, &c));
        return c;
    }

    /// All events so far.
    std::vector<Event> events() const {
        int64_t count = 0;
        check(fricont_path_event_count(h_, &count));
        std::vector<Event> out;
        out.reserve(static_cast<std::size_t>(count));
        for (int64_t k = 0; k < count; k++) {
            fricont_event e{};
            check(fricont_path_event(h_, k, &e));
            out.push_back(Event{e.index, e.transition, e.alpha, e.node,
                                static_cast<Class>(e.from), static_cast<Class>(e.to), e.fold,
                                e.bifurcation, e.residual});
        }
        return out;
    }
    /// The full state at event k (0-based).
    State event_state(int64_t k) const {
        return fill([&](fricont_state *s) { return fricont_path_event_state(h_, k, s); });
    }
    /// The start point.
    State start_state() const {
        return fill([&](fricont_state *s) { return fricont_path_start_state(h_, s); });
    }
    /// The current point (may call the load callback).
    State current() {
        return fill([&](fricont_state *s) { return fricont_path_current(h_, s); });
    }

    /// The traced pieces.
    std::vector<Piece> pieces() const {
        int64_t count = 0;
        check(fricont_path_piece_count(h_, &count));
        std::vector<Piece> out;
        for (int64_t k = 0; k < count; k++) {
            fricont_piece pc{};
            std::vector<int32_t> cls(static_cast<std::size_t>(p_));
            check(fricont_path_piece(h_, k, &pc, cls.data(), p_));
            out.push_back(Piece{pc.alpha_from, pc.alpha_to, pc.direction, pc.orientation,
                                pc.det_sign, detail::to_classes(cls)});
        }
        return out;
    }
    /// The candidate branches at the last transition (empty unless a bifurcation).
    std::vector<Branch> branches() const {
        int64_t count = 0;
        check(fricont_path_branch_count(h_, &count));
        std::vector<Branch> out;
        for (int64_t k = 0; k < count; k++) {
            fricont_branch b{};
            std::vector<int32_t> cls(static_cast<std::size_t>(p_));
            check(fricont_path_branch(h_, k, &b, cls.data(), p_));
            out.push_back(Branch{b.direction, b.orientation_preserving, detail::to_classes(cls)});
        }
        return out;
    }
    /// Continue along candidate branch k of the last bifurcation.
    void choose_branch(int64_t k) { check(fricont_path_choose_branch(h_, k)); }

    /// Every traced solution at α (several past a fold; none if never reached).
    std::vector<Solution> solutions_at(double alpha) {
        int64_t count = 0;
        check(fricont_path_solutions_at(h_, alpha, &count));
        std::vector<Solution> out;
        for (int64_t k = 0; k < count; k++) {
            fricont_solution info{};
            State s = fill([&](fricont_state *st) {
                return fricont_path_solution(h_, k, &info, st);
            });
            out.push_back(Solution{info.piece, info.continuum, std::move(s)});
        }
        return out;
    }

    /// The C handle (still owned by this object).
    fricont_path *get() const noexcept { return h_; }

private:
    explicit Path(Problem &problem) : n_(problem.n()), p_(problem.p()) {}

    template <class F> State fill(F call) const {
        State s;
        s.u.resize(static_cast<std::size_t>(n_));
        s.lambda_n.resize(static_cast<std::size_t>(p_));
        s.lambda_t.resize(static_cast<std::size_t>(p_));
        std::vector<int32_t> cls(static_cast<std::size_t>(p_));
        // (no u for a problem made from condensed data: n = 0, pass NULL)
        fricont_state st{0.0, 0.0, n_ ? s.u.data() : nullptr, n_, s.lambda_n.data(), p_, s.lambda_t.data(),
                         p_, cls.data(), p_};
        check(call(&st));
        s.alpha = st.alpha;
        s.residual = st.residual;
        s.classes = detail::to_classes(cls);
        return s;
    }

    // Rethrows an exception a load callback or the monitor raised during the call that
    // just returned, else throws `Error` with the handle's message for a negative status.
    int32_t check(int32_t st) const {
        if (ctx_ && ctx_->pending) {
            std::exception_ptr e = std::exchange(ctx_->pending, nullptr);
            std::rethrow_exception(e);
        }
        if (pending_ && *pending_) {
            std::exception_ptr e = std::exchange(*pending_, nullptr);
            std::rethrow_exception(e);
        }
        if (st < 0) {
            std::string msg(fricont_path_error_message(h_, nullptr, 0), '\0');
            if (!msg.empty()) fricont_path_error_message(h_, &msg[0], msg.size() + 1);
            else msg = detail::last_error();
            throw Error(st, msg);
        }
        return st;
    }

    fricont_path *h_ = nullptr;
    detail::LoadContext *ctx_ = nullptr;  // owned by the library (freed with the path)
    // an exception of the monitor, shared with its context (see set_monitor)
    std::shared_ptr<std::exception_ptr> pending_;
    int64_t n_ = 0;
    int64_t p_ = 0;
};

}  // namespace fricont

#endif  // FRICONT_HPP
