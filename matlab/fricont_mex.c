/*
 * fricont_mex: the one MEX gateway of the MATLAB/Octave binding.
 *
 *   out = fricont_mex(COMMAND, ...)
 *
 * Called by the .m functions of this directory (fricont_trace, fricont_solutions_at,
 * fricont_handle); not meant to be called directly. Handles are uint64 ids checked
 * against a registry (an unknown or freed id is an error, never a crash); the MEX file
 * is locked (mexLock) while any handle is alive and frees everything at exit.
 *
 * Loads and monitors given as MATLAB function handles. A MATLAB function must not run
 * inside a library call: an error in it would unwind (longjmp or C++ exception) through
 * the library's Rust frames (mexCallMATLABWithTrap traps errors; this way nothing of
 * MATLAB's, an interrupt included, runs under library frames). So a path with such a
 * load or monitor runs its library calls on a worker thread, and the callback (on that
 * thread) hands the request back to MATLAB:
 *
 *   [what, value] = fricont_mex('path_call', id, job, ...)  % 'start', 'run', 'step',
 *                                                           % 'solutions_at',
 *                                                           % 'choose_branch'
 *   while what is not 'done':   % the library waits for f(value) or f'(value) ('f',
 *                               % 'df') or for the monitor ('monitor', value = [alpha,
 *                               % transitions, first_event, last_event], from 1)
 *       [what, value] = fricont_mex('resume', id, reply)  % f(value), or true/false
 *   end                                                   % (stop?), or [] to refuse
 *   % what is 'done', value the fricont_status of the job
 *
 * The MATLAB function is thus evaluated by MATLAB between MEX calls, on MATLAB's own
 * thread; the library sees only a callback that returns 0 or a nonzero code. The worker
 * never calls the MEX or mx API. A path with an affine load has no worker until it is
 * run with a monitor ('path_call', id, 'run', 1); without one 'path_call' returns
 * 'done' at once. While MATLAB holds a request (its function runs), the path is busy:
 * any other command on it but 'free' is an error (a load function or monitor calling
 * into its own path), until the request is answered or 'settle' abandons it (the .m
 * driver calls 'settle' on its way out, also after an error or Ctrl-C).
 *
 * Index conventions: MATLAB's sparse matrices are CSC with 0-based mwIndex arrays; the
 * CSC arrays of a matrix M are the CSR arrays of M.', so A (symmetric) is passed as
 * is and N, T as N.', T.' (the .m functions do it). Everything returned counts from 1.
 */
#include "mex.h"

#include <fricont.h>

#include <pthread.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- Raising errors ------------------------------------------------------------------
 * Octave's mexErrMsgIdAndTxt puts the MEX file's name in front of every message
 * ("fricont_mex: fricont: ..."); MATLAB's does not. So errors are raised by calling
 * MATLAB's error() with a struct {message, identifier}: the same text in both. The
 * macro below routes every mexErrMsgIdAndTxt of this file there. Like
 * mexErrMsgIdAndTxt, it does not return (error() unwinds out of the MEX function). */
static void raise_error(const char *id, const char *fmt, ...) {
    char msg[1400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    const char *fields[] = {"message", "identifier"};
    mxArray *err = mxCreateStructMatrix(1, 1, 2, fields);
    mxSetField(err, 0, "message", mxCreateString(msg));
    mxSetField(err, 0, "identifier", mxCreateString(id));
    mexCallMATLAB(0, NULL, 1, &err, "error");
    mexErrMsgIdAndTxt(id, "%s", msg); /* not reached */
}
#define mexErrMsgIdAndTxt raise_error

/* ---- Worker thread (paths with a MATLAB-function load) ---------------------------- */

enum { W_IDLE, W_JOB, W_RUNNING, W_WAIT_REPLY, W_REPLY_READY, W_DONE, W_QUIT };
enum { JOB_START, JOB_RUN, JOB_STEP, JOB_SOLUTIONS_AT, JOB_CHOOSE_BRANCH };
enum { REQ_F, REQ_DF, REQ_MONITOR, REQ_WEIGHTS };

typedef struct worker {
    pthread_t thread;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int state;
    int abort_calls; /* set when MATLAB abandons a job: callbacks refuse at once */
    int driving;     /* MATLAB's thread only: a request of the job is in MATLAB's hands */
    fricont_path *path;
    /* the job */
    int job;
    double job_alpha;
    double *job_guess;
    int64_t job_guess_len;
    int64_t job_branch; /* JOB_CHOOSE_BRANCH: the candidate, 0-based */
    int32_t job_status;
    int64_t job_count;
    /* the pending request: f or f' at req_alpha into req_out, or the monitor */
    int req_kind;
    double req_alpha;
    double *req_out;
    int64_t req_n;
    int64_t req_transitions, req_first, req_end;
    int32_t reply_code;
    /* a basis load's weights: phi then phi' (2k values) as MATLAB returns them */
    double *weights_buf;
} worker;

/* Hands a request to MATLAB's thread and waits for the reply: 0, or nonzero to refuse
 * (load) or stop (monitor); 2 when MATLAB abandoned the job. */
static int32_t worker_callback(worker *w, int kind, double alpha, double *out, int64_t n,
                               int64_t transitions, int64_t first, int64_t end) {
    int32_t code;
    pthread_mutex_lock(&w->mu);
    if (w->abort_calls) {
        pthread_mutex_unlock(&w->mu);
        return 2;
    }
    w->req_kind = kind;
    w->req_alpha = alpha;
    w->req_out = out;
    w->req_n = n;
    w->req_transitions = transitions;
    w->req_first = first;
    w->req_end = end;
    w->state = W_WAIT_REPLY;
    pthread_cond_broadcast(&w->cv);
    while (w->state == W_WAIT_REPLY && !w->abort_calls) pthread_cond_wait(&w->cv, &w->mu);
    code = w->abort_calls && w->state == W_WAIT_REPLY ? 2 : w->reply_code;
    w->state = W_RUNNING;
    w->req_out = NULL;
    pthread_mutex_unlock(&w->mu);
    return code;
}

static int32_t load_cb(double alpha, double *out, int64_t n, void *ud) {
    return worker_callback((worker *)ud, REQ_F, alpha, out, n, 0, 0, 0);
}

static int32_t dload_cb(double alpha, double *out, int64_t n, void *ud) {
    return worker_callback((worker *)ud, REQ_DF, alpha, out, n, 0, 0, 0);
}

/* A basis load's weights: one request for [phi; phi'] (2k values), split here. */
static int32_t weights_cb(double alpha, double *phi, double *dphi, int64_t k, void *ud) {
    worker *w = (worker *)ud;
    int32_t code = worker_callback(w, REQ_WEIGHTS, alpha, w->weights_buf, 2 * k, 0, 0, 0);
    if (code == 0) {
        memcpy(phi, w->weights_buf, sizeof(double) * (size_t)k);
        memcpy(dphi, w->weights_buf + k, sizeof(double) * (size_t)k);
    }
    return code;
}

static int32_t monitor_cb(double alpha, int64_t transitions, int64_t first, int64_t end,
                          void *ud) {
    return worker_callback((worker *)ud, REQ_MONITOR, alpha, NULL, 0, transitions, first, end);
}

static void *worker_main(void *arg) {
    worker *w = (worker *)arg;
    pthread_mutex_lock(&w->mu);
    for (;;) {
        while (w->state != W_JOB && w->state != W_QUIT) pthread_cond_wait(&w->cv, &w->mu);
        if (w->state == W_QUIT) break;
        w->state = W_RUNNING;
        pthread_mutex_unlock(&w->mu);
        int32_t st;
        int64_t count = 0;
        switch (w->job) {
        case JOB_START:
            st = fricont_path_start(w->path, w->job_alpha, w->job_guess, w->job_guess_len);
            break;
        case JOB_RUN: st = fricont_path_run(w->path); break;
        case JOB_STEP: st = fricont_path_step(w->path); break;
        case JOB_CHOOSE_BRANCH: st = fricont_path_choose_branch(w->path, w->job_branch); break;
        default: st = fricont_path_solutions_at(w->path, w->job_alpha, &count); break;
        }
        pthread_mutex_lock(&w->mu);
        w->job_status = st;
        w->job_count = count;
        w->state = W_DONE;
        pthread_cond_broadcast(&w->cv);
    }
    pthread_mutex_unlock(&w->mu);
    return NULL;
}

/* Waits (on MATLAB's thread) until the job is done or the callback waits for a load. */
static int worker_wait(worker *w) {
    int s;
    pthread_mutex_lock(&w->mu);
    while (w->state != W_DONE && w->state != W_WAIT_REPLY) pthread_cond_wait(&w->cv, &w->mu);
    s = w->state;
    pthread_mutex_unlock(&w->mu);
    return s;
}

/* Ends a job MATLAB left waiting for a load (an error or Ctrl-C in the .m code): the
 * callback refuses, the library call returns FRICONT_ERR_CALLBACK, the path ends. */
static void worker_settle(worker *w) {
    pthread_mutex_lock(&w->mu);
    if (w->state == W_JOB || w->state == W_RUNNING || w->state == W_WAIT_REPLY ||
        w->state == W_REPLY_READY) {
        w->abort_calls = 1;
        pthread_cond_broadcast(&w->cv);
        while (w->state != W_DONE) pthread_cond_wait(&w->cv, &w->mu);
    }
    w->abort_calls = 0;
    w->driving = 0;
    w->state = W_IDLE;
    pthread_mutex_unlock(&w->mu);
}

/* A worker for `path`, its thread started; NULL if that fails. */
static worker *worker_new(fricont_path *path) {
    worker *w = (worker *)calloc(1, sizeof *w);
    if (!w) return NULL;
    pthread_mutex_init(&w->mu, NULL);
    pthread_cond_init(&w->cv, NULL);
    w->state = W_IDLE;
    w->path = path;
    if (pthread_create(&w->thread, NULL, worker_main, w) != 0) {
        pthread_cond_destroy(&w->cv);
        pthread_mutex_destroy(&w->mu);
        free(w);
        return NULL;
    }
    return w;
}

static void worker_stop(worker *w) {
    worker_settle(w);
    pthread_mutex_lock(&w->mu);
    w->state = W_QUIT;
    pthread_cond_broadcast(&w->cv);
    pthread_mutex_unlock(&w->mu);
    pthread_join(w->thread, NULL);
    pthread_cond_destroy(&w->cv);
    pthread_mutex_destroy(&w->mu);
    free(w->job_guess);
    free(w->weights_buf);
    free(w);
}

/* ---- Handle registry ------------------------------------------------------------- */

enum { KIND_PROBLEM = 1, KIND_PATH = 2 };

typedef struct entry {
    uint64_t id;
    int kind;
    fricont_problem *problem;
    fricont_path *path;
    worker *w; /* NULL for a path without MATLAB-function load */
    int64_t n, p;
    struct entry *next;
} entry;

static entry *registry = NULL;
static uint64_t next_id = 1;
static int locked = 0;

static void free_entry(entry *e) {
    if (e->w) worker_stop(e->w);
    fricont_path_free(e->path);
    fricont_problem_free(e->problem);
    free(e);
}

static void free_all(void) {
    while (registry) {
        entry *e = registry;
        registry = e->next;
        free_entry(e);
    }
    if (locked) {
        mexUnlock();
        locked = 0;
    }
}

static entry *add_entry(int kind) {
    entry *e = (entry *)calloc(1, sizeof *e);
    if (!e) mexErrMsgIdAndTxt("fricont:memory", "fricont: out of memory");
    e->id = next_id++;
    e->kind = kind;
    e->next = registry;
    registry = e;
    if (!locked) {
        mexLock();
        locked = 1;
    }
    return e;
}

static void remove_entry(uint64_t id) {
    for (entry **pe = &registry; *pe; pe = &(*pe)->next) {
        if ((*pe)->id == id) {
            entry *e = *pe;
            *pe = e->next;
            free_entry(e);
            break;
        }
    }
    if (!registry && locked) {
        mexUnlock();
        locked = 0;
    }
}

static uint64_t get_id(const mxArray *a) {
    if (!mxIsUint64(a) || mxGetNumberOfElements(a) != 1 || mxIsComplex(a))
        mexErrMsgIdAndTxt("fricont:handle", "fricont: a handle must be a uint64 scalar");
    return *(const uint64_t *)mxGetData(a);
}

static entry *lookup(const mxArray *a, int kind) {
    uint64_t id = get_id(a);
    for (entry *e = registry; e; e = e->next)
        if (e->id == id) {
            if (e->kind != kind)
                mexErrMsgIdAndTxt("fricont:handle", "fricont: handle %llu is a %s, not a %s",
                                  (unsigned long long)id,
                                  e->kind == KIND_PATH ? "path" : "problem",
                                  kind == KIND_PATH ? "path" : "problem");
            return e;
        }
    mexErrMsgIdAndTxt("fricont:handle", "fricont: invalid or freed handle %llu",
                      (unsigned long long)id);
    return NULL;
}

static mxArray *id_array(uint64_t id) {
    mxArray *a = mxCreateNumericMatrix(1, 1, mxUINT64_CLASS, mxREAL);
    *(uint64_t *)mxGetData(a) = id;
    return a;
}

/* ---- Errors: raised only here, on MATLAB's side, after the library call returned --- */

static void raise_status(int32_t st, const char *what) {
    char msg[1024];
    size_t len = fricont_last_error_message(msg, sizeof msg);
    const char *name = fricont_status_str(st);
    char id[64];
    /* "FRICONT_ERR_CSR: ..." -> identifier fricont:ERR_CSR */
    size_t k = 0;
    const char *s = strncmp(name, "FRICONT_", 8) == 0 ? name + 8 : "unknown";
    while (s[k] && s[k] != ':' && k < sizeof id - 10) k++;
    snprintf(id, sizeof id, "fricont:%.*s", (int)k, s);
    /* The library's message names the argument and the cause ("A (CSR): ..."); `what`
     * (the request that ran into it, e.g. the first call that factorises A) only stands
     * in when there is no message. */
    if (len)
        mexErrMsgIdAndTxt(id, "fricont: %s", msg);
    else
        mexErrMsgIdAndTxt(id, "fricont: %s: %s", what, name);
}

static void check(int32_t st, const char *what) {
    if (st < 0) raise_status(st, what);
}

/* ---- Argument helpers ------------------------------------------------------------ */

static double get_scalar(const mxArray *a, const char *what) {
    if (!mxIsDouble(a) || mxIsComplex(a) || mxIsSparse(a) || mxGetNumberOfElements(a) != 1)
        mexErrMsgIdAndTxt("fricont:argument", "fricont: %s must be a real double scalar", what);
    return mxGetScalar(a);
}

static const double *get_vector(const mxArray *a, int64_t len, const char *what) {
    if (!mxIsDouble(a) || mxIsComplex(a) || mxIsSparse(a))
        mexErrMsgIdAndTxt("fricont:argument", "fricont: %s must be a real full double array",
                          what);
    if (len >= 0 && (int64_t)mxGetNumberOfElements(a) != len)
        mexErrMsgIdAndTxt("fricont:argument", "fricont: %s has %llu values, expected %lld",
                          what, (unsigned long long)mxGetNumberOfElements(a), (long long)len);
    return mxGetPr(a);
}

static void get_string(const mxArray *a, char *buf, size_t len, const char *what) {
    if (!mxIsChar(a) || mxGetString(a, buf, (mwSize)len) != 0)
        mexErrMsgIdAndTxt("fricont:argument", "fricont: %s must be a short string", what);
}

/* A sparse matrix M (rows x cols) as the CSR of M.' : cols rows, rows columns. The
 * index arrays are used in place when mwIndex is 64 bits wide, else copied. */
typedef struct {
    fricont_csr csr;
    int64_t *owned_ptr, *owned_idx;
} csr_view;

static csr_view sparse_transposed_as_csr(const mxArray *m, const char *what) {
    csr_view v;
    memset(&v, 0, sizeof v);
    if (!mxIsSparse(m) || !mxIsDouble(m) || mxIsComplex(m))
        mexErrMsgIdAndTxt("fricont:argument", "fricont: %s must be a real sparse matrix", what);
    size_t rows = mxGetM(m), cols = mxGetN(m);
    const mwIndex *jc = mxGetJc(m), *ir = mxGetIr(m);
    size_t nnz = jc[cols];
    v.csr.nrows = (int64_t)cols;
    v.csr.ncols = (int64_t)rows;
    v.csr.nnz = (int64_t)nnz;
    v.csr.values = mxGetPr(m);
    v.csr.index_base = 0;
    if (sizeof(mwIndex) == sizeof(int64_t)) {
        v.csr.row_ptr = (const int64_t *)(const void *)jc;
        v.csr.col_idx = (const int64_t *)(const void *)ir;
    } else {
        v.owned_ptr = (int64_t *)mxMalloc(sizeof(int64_t) * (cols + 1));
        v.owned_idx = (int64_t *)mxMalloc(sizeof(int64_t) * (nnz ? nnz : 1));
        for (size_t i = 0; i <= cols; i++) v.owned_ptr[i] = (int64_t)jc[i];
        for (size_t k = 0; k < nnz; k++) v.owned_idx[k] = (int64_t)ir[k];
        v.csr.row_ptr = v.owned_ptr;
        v.csr.col_idx = v.owned_idx;
    }
    return v;
}

static void csr_view_free(csr_view *v) {
    if (v->owned_ptr) mxFree(v->owned_ptr);
    if (v->owned_idx) mxFree(v->owned_idx);
}

/* ---- Output helpers -------------------------------------------------------------- */

static mxArray *column(const double *x, int64_t len) {
    mxArray *a = mxCreateDoubleMatrix((mwSize)len, 1, mxREAL);
    if (len) memcpy(mxGetPr(a), x, sizeof(double) * (size_t)len);
    return a;
}

static mxArray *class_cells(const int32_t *classes, int64_t p) {
    mxArray *c = mxCreateCellMatrix((mwSize)p, 1);
    for (int64_t i = 0; i < p; i++)
        mxSetCell(c, (mwIndex)i, mxCreateString(fricont_class_name(classes[i])));
    return c;
}

static mxArray *logical(int v) { return mxCreateLogicalScalar(v ? true : false); }

/* A state as a struct with alpha, residual, u, lambda_n, lambda_t, classes. */
typedef struct {
    fricont_state st;
    double *u, *ln, *lt;
    int32_t *cls;
} state_buf;

static void state_buf_init(state_buf *b, int64_t n, int64_t p) {
    b->u = (double *)mxCalloc((size_t)(n ? n : 1), sizeof(double));
    b->ln = (double *)mxCalloc((size_t)(p ? p : 1), sizeof(double));
    b->lt = (double *)mxCalloc((size_t)(p ? p : 1), sizeof(double));
    b->cls = (int32_t *)mxCalloc((size_t)(p ? p : 1), sizeof(int32_t));
    memset(&b->st, 0, sizeof b->st);
    b->st.u = b->u;
    b->st.u_len = n;
    b->st.lambda_n = b->ln;
    b->st.lambda_n_len = p;
    b->st.lambda_t = b->lt;
    b->st.lambda_t_len = p;
    b->st.classes = b->cls;
    b->st.classes_len = p;
}

static void state_buf_free(state_buf *b) {
    mxFree(b->u);
    mxFree(b->ln);
    mxFree(b->lt);
    mxFree(b->cls);
}

static void set_state_fields(mxArray *s, mwIndex k, const state_buf *b, int64_t n, int64_t p) {
    mxSetField(s, k, "alpha", mxCreateDoubleScalar(b->st.alpha));
    mxSetField(s, k, "residual", mxCreateDoubleScalar(b->st.residual));
    mxSetField(s, k, "u", column(b->u, n));
    mxSetField(s, k, "lambda_n", column(b->ln, p));
    mxSetField(s, k, "lambda_t", column(b->lt, p));
    mxSetField(s, k, "classes", class_cells(b->cls, p));
}

static const char *state_fields[] = {"alpha", "residual", "u", "lambda_n", "lambda_t", "classes"};

/* ---- Commands -------------------------------------------------------------------- */

#define NEED(k)                                                                        \
    do {                                                                               \
        if (nrhs < (k))                                                                \
            mexErrMsgIdAndTxt("fricont:argument", "fricont_mex %s: needs %d arguments", \
                              cmd, (k)-1);                                             \
    } while (0)

/* 'path_call' for a path without worker: runs the job here and returns ('done', status). */
static int32_t run_job_direct(entry *e, int job, double alpha, const double *guess,
                              int64_t guess_len, int64_t branch, int64_t *count) {
    switch (job) {
    case JOB_START: return fricont_path_start(e->path, alpha, guess, guess_len);
    case JOB_RUN: return fricont_path_run(e->path);
    case JOB_STEP: return fricont_path_step(e->path);
    case JOB_CHOOSE_BRANCH: return fricont_path_choose_branch(e->path, branch);
    default: return fricont_path_solutions_at(e->path, alpha, count);
    }
}

/* Returns [what, value] after a job finished or a load or the monitor was requested. */
static void job_outputs(int nlhs, mxArray *plhs[], entry *e, int32_t status, int64_t count,
                        int waiting) {
    if (waiting && e->w->req_kind == REQ_MONITOR) {
        worker *w = e->w;
        plhs[0] = mxCreateString("monitor");
        plhs[1] = mxCreateDoubleMatrix(1, 4, mxREAL);
        double *v = mxGetPr(plhs[1]);
        v[0] = w->req_alpha;
        v[1] = (double)w->req_transitions;
        v[2] = (double)(w->req_first + 1); /* the new events, from 1, last included */
        v[3] = (double)w->req_end;
    } else if (waiting) {
        plhs[0] = mxCreateString(e->w->req_kind == REQ_DF        ? "df"
                                 : e->w->req_kind == REQ_WEIGHTS ? "w"
                                                                 : "f");
        plhs[1] = mxCreateDoubleScalar(e->w->req_alpha);
    } else {
        plhs[0] = mxCreateString("done");
        plhs[1] = mxCreateDoubleScalar((double)status);
        if (nlhs > 2) plhs[2] = mxCreateDoubleScalar((double)count);
    }
    if (nlhs > 2 && waiting) plhs[2] = mxCreateDoubleScalar(0.0);
}

static void finish_job(int nlhs, mxArray *plhs[], entry *e) {
    int s = worker_wait(e->w);
    if (s == W_DONE) {
        int32_t st;
        int64_t count;
        pthread_mutex_lock(&e->w->mu);
        st = e->w->job_status;
        count = e->w->job_count;
        e->w->state = W_IDLE;
        pthread_mutex_unlock(&e->w->mu);
        e->w->driving = 0;
        job_outputs(nlhs, plhs, e, st, count, 0);
    } else {
        e->w->driving = 1;
        job_outputs(nlhs, plhs, e, 0, 0, 1);
    }
}

/* The path of prhs[1], with no job running: a job MATLAB abandoned earlier (an error or
 * Ctrl-C in the .m code, without 'settle') ends now. A request still in MATLAB's hands
 * means that its load function or monitor calls into its own path: an error. */
static entry *idle_path(const mxArray *id) {
    entry *e = lookup(id, KIND_PATH);
    if (e->w && e->w->driving)
        mexErrMsgIdAndTxt("fricont:order", "fricont: the path is in use: its own load "
                                           "function or monitor called into it");
    if (e->w) worker_settle(e->w);
    return e;
}

static void cmd_path_call(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[],
                          const char *cmd) {
    NEED(3);
    entry *e = idle_path(prhs[1]);
    char job_name[32];
    get_string(prhs[2], job_name, sizeof job_name, "job");
    int job;
    double alpha = 0;
    const double *guess = NULL;
    int64_t guess_len = 0;
    int64_t branch = 0;
    int monitored = 0;
    if (strcmp(job_name, "start") == 0) {
        NEED(4);
        job = JOB_START;
        alpha = get_scalar(prhs[3], "alpha");
        if (nrhs > 4 && !mxIsEmpty(prhs[4])) {
            guess = get_vector(prhs[4], -1, "guess");
            guess_len = (int64_t)mxGetNumberOfElements(prhs[4]);
        }
    } else if (strcmp(job_name, "run") == 0) {
        /* ('path_call', id, 'run', monitored): with monitored nonzero the library calls
         * the monitor after each transition point, and MATLAB answers it. */
        job = JOB_RUN;
        monitored = nrhs > 3 && get_scalar(prhs[3], "monitored") != 0;
    } else if (strcmp(job_name, "step") == 0) {
        job = JOB_STEP;
    } else if (strcmp(job_name, "choose_branch") == 0) {
        /* ('path_call', id, 'choose_branch', k): candidate k, 1-based as MATLAB counts */
        NEED(4);
        job = JOB_CHOOSE_BRANCH;
        double k = get_scalar(prhs[3], "branch");
        if (!(k >= 1 && k <= 9.0e15 && k == (double)(int64_t)k))
            mexErrMsgIdAndTxt("fricont:argument",
                              "fricont: the branch must be a positive integer (1-based)");
        branch = (int64_t)k - 1;
    } else if (strcmp(job_name, "solutions_at") == 0) {
        NEED(4);
        job = JOB_SOLUTIONS_AT;
        alpha = get_scalar(prhs[3], "alpha");
    } else {
        mexErrMsgIdAndTxt("fricont:argument", "fricont_mex path_call: unknown job '%s'",
                          job_name);
        return;
    }
    if (monitored && !e->w) { /* an affine path: its first monitored run */
        e->w = worker_new(e->path);
        if (!e->w) mexErrMsgIdAndTxt("fricont:thread", "fricont: cannot start a worker thread");
    }
    if (job == JOB_RUN && e->w)
        check(fricont_path_set_monitor(e->path, monitored ? monitor_cb : NULL, e->w, NULL),
              "monitor");
    if (!e->w) {
        int64_t count = 0;
        int32_t st = run_job_direct(e, job, alpha, guess, guess_len, branch, &count);
        job_outputs(nlhs, plhs, e, st, count, 0);
        return;
    }
    worker *w = e->w;
    pthread_mutex_lock(&w->mu);
    free(w->job_guess);
    w->job_guess = NULL;
    w->job_guess_len = guess_len;
    if (guess_len) {
        w->job_guess = (double *)malloc(sizeof(double) * (size_t)guess_len);
        if (!w->job_guess) {
            pthread_mutex_unlock(&w->mu);
            mexErrMsgIdAndTxt("fricont:memory", "fricont: out of memory");
        }
        memcpy(w->job_guess, guess, sizeof(double) * (size_t)guess_len);
    }
    w->job = job;
    w->job_alpha = alpha;
    w->job_branch = branch;
    w->state = W_JOB;
    pthread_cond_broadcast(&w->cv);
    pthread_mutex_unlock(&w->mu);
    finish_job(nlhs, plhs, e);
}

static void cmd_resume(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[],
                       const char *cmd) {
    NEED(3);
    entry *e = lookup(prhs[1], KIND_PATH);
    worker *w = e->w;
    if (!w) mexErrMsgIdAndTxt("fricont:order", "fricont: resume on a path without worker");
    pthread_mutex_lock(&w->mu);
    int waiting = w->state == W_WAIT_REPLY;
    pthread_mutex_unlock(&w->mu);
    if (!waiting) mexErrMsgIdAndTxt("fricont:order", "fricont: no request is pending");
    const mxArray *v = prhs[2];
    int32_t code = 0;
    if (mxIsEmpty(v)) {
        code = 1; /* MATLAB refused: its function raised an error (a monitor: stop) */
    } else if (w->req_kind == REQ_MONITOR) {
        /* stop?: the .m code checks that it is a logical or 0/1 scalar */
        code = (mxIsLogical(v) || mxIsNumeric(v)) && mxGetNumberOfElements(v) == 1 &&
                       mxGetScalar(v) == 0
                   ? 0
                   : 1;
    } else if (!mxIsDouble(v) || mxIsComplex(v) || mxIsSparse(v) ||
               (int64_t)mxGetNumberOfElements(v) != w->req_n) {
        code = 3; /* wrong type or length: the .m code checks first, this is a guard */
    }
    pthread_mutex_lock(&w->mu);
    if (code == 0 && w->req_kind != REQ_MONITOR)
        memcpy(w->req_out, mxGetPr(v), sizeof(double) * (size_t)w->req_n);
    w->reply_code = code;
    w->state = W_REPLY_READY;
    pthread_cond_broadcast(&w->cv);
    pthread_mutex_unlock(&w->mu);
    finish_job(nlhs, plhs, e);
}

static void cmd_problem_new(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[],
                            const char *cmd) {
    (void)nlhs;
    NEED(5);
    char storage[16];
    get_string(prhs[2], storage, sizeof storage, "storage");
    /* The CSC arrays of MATLAB's A are the CSR arrays of A.': a lower triangle given
     * in MATLAB is an upper triangle for the library. */
    int32_t code;
    if (strcmp(storage, "full") == 0) code = FRICONT_STORAGE_FULL;
    else if (strcmp(storage, "lower") == 0) code = FRICONT_STORAGE_UPPER;
    else if (strcmp(storage, "upper") == 0) code = FRICONT_STORAGE_LOWER;
    else {
        mexErrMsgIdAndTxt("fricont:argument", "fricont: storage is 'full', 'lower' or 'upper'");
        return;
    }
    csr_view a = sparse_transposed_as_csr(prhs[1], "A");
    csr_view n = sparse_transposed_as_csr(prhs[3], "N.'");
    csr_view t = sparse_transposed_as_csr(prhs[4], "T.'");
    fricont_problem *prob = NULL;
    int32_t st = fricont_problem_new(&a.csr, code, &n.csr, &t.csr, &prob);
    csr_view_free(&a);
    csr_view_free(&n);
    csr_view_free(&t);
    check(st, "problem");
    entry *e = add_entry(KIND_PROBLEM);
    e->problem = prob;
    check(fricont_problem_dims(prob, &e->n, &e->p), "problem dims");
    plhs[0] = id_array(e->id);
}

static void cmd_problem_set(int nrhs, const mxArray *prhs[], const char *cmd) {
    NEED(4);
    entry *e = lookup(prhs[1], KIND_PROBLEM);
    char what[16];
    get_string(prhs[2], what, sizeof what, "setting");
    if (strcmp(what, "friction") == 0) {
        if (mxGetNumberOfElements(prhs[3]) == 1)
            check(fricont_problem_set_friction(e->problem, get_scalar(prhs[3], "F")), "F");
        else
            check(fricont_problem_set_friction_nodes(
                      e->problem, get_vector(prhs[3], -1, "F"),
                      (int64_t)mxGetNumberOfElements(prhs[3])),
                  "F");
    } else if (strcmp(what, "gap") == 0) {
        check(fricont_problem_set_gap(e->problem, get_vector(prhs[3], -1, "gap"),
                                      (int64_t)mxGetNumberOfElements(prhs[3])),
              "gap");
    } else if (strcmp(what, "r") == 0) {
        check(fricont_problem_set_r(e->problem, get_scalar(prhs[3], "r")), "r");
    } else if (strcmp(what, "extended") == 0) {
        /* 0 auto, 1 on, 2 off (the .m code maps the names) */
        check(fricont_problem_set_extended_precision(
                  e->problem, (int32_t)get_scalar(prhs[3], "extended_precision")),
              "extended_precision");
    } else {
        mexErrMsgIdAndTxt("fricont:argument", "fricont: unknown problem setting '%s'", what);
    }
}

enum { PATH_AFFINE, PATH_GENERAL, PATH_BASIS };

/* ('path_new_affine', prob, f0, f1), ('path_new_general', prob, has_derivative) or
 * ('path_new_basis', prob, V): V n-by-k, the vectors of a basis load whose weights
 * MATLAB returns as [phi; phi'] (request 'w'). A path with a MATLAB function gets a
 * worker thread. */
static void cmd_path_new(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[],
                         const char *cmd, int kind) {
    (void)nlhs;
    NEED(kind == PATH_AFFINE ? 4 : 3);
    entry *pe = lookup(prhs[1], KIND_PROBLEM);
    fricont_path *path = NULL;
    worker *w = NULL;
    if (kind == PATH_AFFINE) {
        const double *f0 = get_vector(prhs[2], pe->n, "f0");
        const double *f1 = get_vector(prhs[3], pe->n, "f1");
        check(fricont_path_new_affine(pe->problem, f0, f1, pe->n, &path), "path");
    } else {
        /* the arguments checked before the worker exists: an error leaves nothing behind */
        const mxArray *v = prhs[2];
        int64_t k = 0;
        int with_derivative = 0;
        if (kind == PATH_BASIS) {
            if (!mxIsDouble(v) || mxIsComplex(v) || mxIsSparse(v) ||
                (int64_t)mxGetM(v) != pe->n || mxGetN(v) < 1)
                mexErrMsgIdAndTxt("fricont:argument",
                                  "fricont: the basis vectors must be a real dense n-by-k "
                                  "matrix (n = %lld rows, k >= 1 columns)",
                                  (long long)pe->n);
            k = (int64_t)mxGetN(v);
        } else {
            with_derivative = get_scalar(v, "has_derivative") != 0;
        }
        w = worker_new(NULL);
        if (!w) mexErrMsgIdAndTxt("fricont:thread", "fricont: cannot start a worker thread");
        int32_t st;
        if (kind == PATH_BASIS) {
            w->weights_buf = (double *)calloc((size_t)(2 * k), sizeof(double));
            if (!w->weights_buf) {
                worker_stop(w);
                mexErrMsgIdAndTxt("fricont:memory", "fricont: out of memory");
            }
            st = fricont_path_new_basis(pe->problem, mxGetPr(v), pe->n, k, weights_cb, w, NULL,
                                        &path);
        } else {
            st = fricont_path_new_general(pe->problem, pe->n, load_cb,
                                          with_derivative ? dload_cb : NULL, w, NULL, &path);
        }
        if (st < 0) {
            worker_stop(w);
            raise_status(st, "path");
        }
        w->path = path; /* read by the worker's thread only for a job, after the mutex */
    }
    entry *e = add_entry(KIND_PATH);
    e->path = path;
    e->w = w;
    e->n = pe->n;
    e->p = pe->p;
    plhs[0] = id_array(e->id);
}

static void cmd_path_set(int nrhs, const mxArray *prhs[], const char *cmd) {
    NEED(4);
    entry *e = idle_path(prhs[1]);
    char what[16];
    get_string(prhs[2], what, sizeof what, "setting");
    if (strcmp(what, "window") == 0) {
        const double *a = get_vector(prhs[3], 2, "window [alpha_start alpha_end]");
        check(fricont_path_set_window(e->path, a[0], a[1]), "window");
    } else if (strcmp(what, "max_steps") == 0) {
        check(fricont_path_set_max_steps(e->path, (int64_t)get_scalar(prhs[3], "max_steps")),
              "max_steps");
    } else if (strcmp(what, "zero_tol") == 0) {
        check(fricont_path_set_zero_tol(e->path, get_scalar(prhs[3], "zero_tol")), "zero_tol");
    } else if (strcmp(what, "max_alpha_step") == 0) {
        check(fricont_path_set_max_alpha_step(e->path, get_scalar(prhs[3], "max_alpha_step")),
              "max_alpha_step");
    } else {
        mexErrMsgIdAndTxt("fricont:argument", "fricont: unknown path setting '%s'", what);
    }
}

/* The candidate branches at the path's last transition point (fricont_path_branch_count:
 * none unless it was a bifurcation and the path has not moved since, or directly after a
 * start that offered several) as a struct array: classes (cell of names), direction,
 * orientation_preserving. `cls` holds p classes. */
static mxArray *branch_array(fricont_path *path, int64_t p, int32_t *cls) {
    int64_t count = 0;
    check(fricont_path_branch_count(path, &count), "branches");
    static const char *fields[] = {"classes", "direction", "orientation_preserving"};
    mxArray *out = mxCreateStructMatrix((mwSize)count, 1, 3, fields);
    for (int64_t k = 0; k < count; k++) {
        fricont_branch br;
        check(fricont_path_branch(path, k, &br, cls, p), "branch");
        mxSetField(out, (mwIndex)k, "classes", class_cells(cls, p));
        mxSetField(out, (mwIndex)k, "direction", mxCreateDoubleScalar(br.direction));
        mxSetField(out, (mwIndex)k, "orientation_preserving", logical(br.orientation_preserving));
    }
    return out;
}

/* The traced path as a struct: events (with states), pieces, start, end. */
static void cmd_path_result(mxArray *plhs[], int nrhs, const mxArray *prhs[], const char *cmd) {
    NEED(2);
    entry *e = idle_path(prhs[1]);
    fricont_path *path = e->path;
    int64_t n = e->n, p = e->p, count = 0, pieces = 0;
    check(fricont_path_event_count(path, &count), "events");
    check(fricont_path_piece_count(path, &pieces), "pieces");
    state_buf b;
    state_buf_init(&b, n, p);

    static const char *ev_fields[] = {"index", "transition", "alpha", "node", "from", "to",
                                      "fold", "bifurcation", "residual", "u", "lambda_n",
                                      "lambda_t", "classes"};
    mxArray *events = mxCreateStructMatrix((mwSize)count, 1, 13, ev_fields);
    for (int64_t k = 0; k < count; k++) {
        fricont_event ev;
        check(fricont_path_event(path, k, &ev), "event");
        check(fricont_path_event_state(path, k, &b.st), "event state");
        mxSetField(events, (mwIndex)k, "index", mxCreateDoubleScalar((double)(ev.index + 1)));
        mxSetField(events, (mwIndex)k, "transition",
                   mxCreateDoubleScalar((double)(ev.transition + 1)));
        mxSetField(events, (mwIndex)k, "alpha", mxCreateDoubleScalar(ev.alpha));
        mxSetField(events, (mwIndex)k, "node", mxCreateDoubleScalar((double)(ev.node + 1)));
        mxSetField(events, (mwIndex)k, "from", mxCreateString(fricont_class_name(ev.from)));
        mxSetField(events, (mwIndex)k, "to", mxCreateString(fricont_class_name(ev.to)));
        mxSetField(events, (mwIndex)k, "fold", logical(ev.fold));
        mxSetField(events, (mwIndex)k, "bifurcation", logical(ev.bifurcation));
        mxSetField(events, (mwIndex)k, "residual", mxCreateDoubleScalar(ev.residual));
        mxSetField(events, (mwIndex)k, "u", column(b.u, n));
        mxSetField(events, (mwIndex)k, "lambda_n", column(b.ln, p));
        mxSetField(events, (mwIndex)k, "lambda_t", column(b.lt, p));
        mxSetField(events, (mwIndex)k, "classes", class_cells(b.cls, p));
    }

    static const char *pc_fields[] = {"alpha_from", "alpha_to", "direction", "orientation",
                                      "det_sign", "classes"};
    mxArray *pcs = mxCreateStructMatrix((mwSize)pieces, 1, 6, pc_fields);
    for (int64_t k = 0; k < pieces; k++) {
        fricont_piece pc;
        check(fricont_path_piece(path, k, &pc, b.cls, p), "piece");
        mxSetField(pcs, (mwIndex)k, "alpha_from", mxCreateDoubleScalar(pc.alpha_from));
        mxSetField(pcs, (mwIndex)k, "alpha_to", mxCreateDoubleScalar(pc.alpha_to));
        mxSetField(pcs, (mwIndex)k, "direction", mxCreateDoubleScalar(pc.direction));
        mxSetField(pcs, (mwIndex)k, "orientation", mxCreateDoubleScalar(pc.orientation));
        mxSetField(pcs, (mwIndex)k, "det_sign", mxCreateDoubleScalar(pc.det_sign));
        mxSetField(pcs, (mwIndex)k, "classes", class_cells(b.cls, p));
    }

    mxArray *start = mxCreateStructMatrix(1, 1, 6, state_fields);
    check(fricont_path_start_state(path, &b.st), "start state");
    set_state_fields(start, 0, &b, n, p);

    int32_t reason = 0, code = 0, route = 0;
    check(fricont_path_end_reason(path, &reason), "end reason");
    check(fricont_path_callback_code(path, &code), "callback code");
    check(fricont_path_start_route(path, &route), "start route");
    static const char *fields[] = {"events", "pieces", "start", "end_reason", "n", "p",
                                   "callback_code", "branches", "start_route"};
    mxArray *out = mxCreateStructMatrix(1, 1, 9, fields);
    mxSetField(out, 0, "branches", branch_array(path, p, b.cls));
    mxSetField(out, 0, "events", events);
    mxSetField(out, 0, "pieces", pcs);
    mxSetField(out, 0, "start", start);
    mxSetField(out, 0, "end_reason", mxCreateString(fricont_end_reason_name(reason)));
    mxSetField(out, 0, "start_route", mxCreateString(fricont_start_route_name(route)));
    mxSetField(out, 0, "n", mxCreateDoubleScalar((double)n));
    mxSetField(out, 0, "p", mxCreateDoubleScalar((double)p));
    mxSetField(out, 0, "callback_code", mxCreateDoubleScalar((double)code));
    state_buf_free(&b);
    plhs[0] = out;
}

/* 'branches', id: the candidate branches now (see branch_array). */
static void cmd_branches(mxArray *plhs[], int nrhs, const mxArray *prhs[], const char *cmd) {
    NEED(2);
    entry *e = idle_path(prhs[1]);
    int32_t *cls = (int32_t *)mxMalloc(sizeof(int32_t) * (size_t)(e->p > 0 ? e->p : 1));
    plhs[0] = branch_array(e->path, e->p, cls);
    mxFree(cls);
}

/* Solutions 1..count of the last solutions_at as a struct array. */
static void cmd_solutions(mxArray *plhs[], int nrhs, const mxArray *prhs[], const char *cmd) {
    NEED(3);
    entry *e = idle_path(prhs[1]);
    int64_t count = (int64_t)get_scalar(prhs[2], "count");
    static const char *fields[] = {"alpha", "residual", "u", "lambda_n", "lambda_t",
                                   "classes", "piece", "continuum"};
    mxArray *out = mxCreateStructMatrix((mwSize)count, 1, 8, fields);
    state_buf b;
    state_buf_init(&b, e->n, e->p);
    for (int64_t k = 0; k < count; k++) {
        fricont_solution info;
        check(fricont_path_solution(e->path, k, &info, &b.st), "solution");
        set_state_fields(out, (mwIndex)k, &b, e->n, e->p);
        mxSetField(out, (mwIndex)k, "piece", mxCreateDoubleScalar((double)(info.piece + 1)));
        mxSetField(out, (mwIndex)k, "continuum", logical(info.continuum));
    }
    state_buf_free(&b);
    plhs[0] = out;
}

static void cmd_error_message(mxArray *plhs[], int nrhs, const mxArray *prhs[],
                              const char *cmd) {
    NEED(2);
    entry *e = idle_path(prhs[1]);
    char msg[1024];
    size_t len = fricont_path_error_message(e->path, msg, sizeof msg);
    if (!len) msg[0] = 0;
    plhs[0] = mxCreateString(msg);
}

void mexFunction(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[]) {
    static int registered = 0;
    if (!registered) {
        mexAtExit(free_all);
        registered = 1;
    }
    if (nrhs < 1 || !mxIsChar(prhs[0]))
        mexErrMsgIdAndTxt("fricont:argument", "fricont_mex: the first argument is a command");
    char cmd[32];
    get_string(prhs[0], cmd, sizeof cmd, "command");

    if (strcmp(cmd, "version") == 0) {
        plhs[0] = mxCreateString(fricont_version());
    } else if (strcmp(cmd, "problem_new") == 0) {
        cmd_problem_new(nlhs, plhs, nrhs, prhs, cmd);
    } else if (strcmp(cmd, "problem_set") == 0) {
        cmd_problem_set(nrhs, prhs, cmd);
    } else if (strcmp(cmd, "problem_r") == 0) {
        NEED(2);
        entry *e = lookup(prhs[1], KIND_PROBLEM);
        double r = 0, d = 0;
        check(fricont_problem_r(e->problem, &r, &d), "r");
        plhs[0] = mxCreateDoubleScalar(r);
        if (nlhs > 1) plhs[1] = mxCreateDoubleScalar(d);
    } else if (strcmp(cmd, "problem_precision") == 0) {
        /* [extended, w_condition] = ('problem_precision', prob): builds the problem */
        NEED(2);
        entry *e = lookup(prhs[1], KIND_PROBLEM);
        int32_t ext = 0;
        double kappa = 0;
        check(fricont_problem_extended_precision(e->problem, &ext, &kappa), "extended_precision");
        plhs[0] = logical(ext);
        if (nlhs > 1) plhs[1] = mxCreateDoubleScalar(kappa);
    } else if (strcmp(cmd, "path_new_affine") == 0) {
        cmd_path_new(nlhs, plhs, nrhs, prhs, cmd, PATH_AFFINE);
    } else if (strcmp(cmd, "path_new_basis") == 0) {
        cmd_path_new(nlhs, plhs, nrhs, prhs, cmd, PATH_BASIS);
    } else if (strcmp(cmd, "path_new_general") == 0) {
        cmd_path_new(nlhs, plhs, nrhs, prhs, cmd, PATH_GENERAL);
    } else if (strcmp(cmd, "path_set") == 0) {
        cmd_path_set(nrhs, prhs, cmd);
    } else if (strcmp(cmd, "path_call") == 0) {
        cmd_path_call(nlhs, plhs, nrhs, prhs, cmd);
    } else if (strcmp(cmd, "resume") == 0) {
        cmd_resume(nlhs, plhs, nrhs, prhs, cmd);
    } else if (strcmp(cmd, "path_result") == 0) {
        cmd_path_result(plhs, nrhs, prhs, cmd);
    } else if (strcmp(cmd, "branches") == 0) {
        cmd_branches(plhs, nrhs, prhs, cmd);
    } else if (strcmp(cmd, "solutions") == 0) {
        cmd_solutions(plhs, nrhs, prhs, cmd);
    } else if (strcmp(cmd, "path_error_message") == 0) {
        cmd_error_message(plhs, nrhs, prhs, cmd);
    } else if (strcmp(cmd, "status_str") == 0) {
        NEED(2);
        plhs[0] = mxCreateString(fricont_status_str((int32_t)get_scalar(prhs[1], "status")));
    } else if (strcmp(cmd, "settle") == 0) {
        /* the .m driver on its way out: a request it left unanswered is refused, the job
         * ends (a monitor's: stopped). An unknown id is a no-op, as for 'free'. */
        NEED(2);
        uint64_t id = get_id(prhs[1]);
        for (entry *e = registry; e; e = e->next)
            if (e->id == id && e->w) worker_settle(e->w);
    } else if (strcmp(cmd, "free") == 0) {
        NEED(2);
        remove_entry(get_id(prhs[1])); /* an unknown id is a no-op, as free(NULL) */
    } else if (strcmp(cmd, "count") == 0) {
        double c = 0;
        for (entry *e = registry; e; e = e->next) c++;
        plhs[0] = mxCreateDoubleScalar(c);
    } else if (strcmp(cmd, "is_locked") == 0) {
        plhs[0] = logical(mexIsLocked());
    } else {
        mexErrMsgIdAndTxt("fricont:argument", "fricont_mex: unknown command '%s'", cmd);
    }
}
