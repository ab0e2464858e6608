function res = fricont_trace(A, N, T, f0, f1, F, window, opts)
%FRICONT_TRACE Trace the solution path of a 2D contact problem with Coulomb friction.
%
%   res = fricont_trace(A, N, T, f0, f1, F, [alpha0 alpha1])
%   res = fricont_trace(A, N, T, f0, f1, F, [alpha0 alpha1], opts)
%   res = fricont_trace(A, N, T, @f, @df, F, [alpha0 alpha1], opts)
%   res = fricont_trace(A, N, T, V, @weights, F, [alpha0 alpha1], opts)
%
%   A      n-by-n stiffness, sparse, symmetric positive definite (Dirichlet dofs
%          eliminated). Passed in MATLAB's own CSC form, not copied before the library
%          copies it (see opts.storage for a triangle).
%   N, T   p-by-n sparse: row i gives the outward normal and the tangential displacement
%          of contact node i ((N u)_i <= gap_i is non-penetration).
%   f0, f1 n-vectors: the affine load f(alpha) = f0 + alpha*f1 (force units of A*u).
%          Or a function handle f(alpha) returning an n-vector, and a function handle
%          df(alpha) for f'(alpha) or [] (then central differences are used). MATLAB
%          evaluates them between library calls; an error they raise stops the trace
%          and is reported by fricont_trace. Each evaluation costs a solve with the
%          piece matrix, and one with A until the evaluations span the load's
%          directions (at most 8; then a combination of those solves).
%          Or a basis load f(alpha) = V * phi(alpha): V an n-by-k matrix of fixed
%          vectors and weights(alpha) a function handle returning the k-by-2 matrix
%          [phi dphi] (the weights and their derivatives). Each column of V is condensed
%          once, so an evaluation costs O(k p) instead of a piece solve: prefer it
%          whenever the load is a combination of fixed vectors (an oscillating amplitude,
%          several load cases), e.g. V = [f0 f1], weights = @(a) [1 0; sin(a) cos(a)].
%   F      friction coefficient, a scalar or a p-vector (>= 0).
%   [alpha0 alpha1]  the window: traced from alpha0 toward alpha1.
%   opts   struct, all fields optional:
%          gap (p-vector, default 0), r (augmentation parameter, default 2p/trace(W)),
%          storage ('full' default, 'lower' or 'upper': which triangle of A is stored),
%          max_steps (default 10000), zero_tol (default 1e-11),
%          guess (2p-vector [lambda_n; lambda_t] for the start solve: the problem at
%            one alpha can have several solutions (large friction, folds); the solve
%            returns one of them, and a guess that solves the problem is kept, so a
%            known solution is traced from exactly),
%          extended_precision ('auto' default, 'on' or 'off'): whether W and the
%            condensed loads are carried beyond double precision (slender bodies, whose W
%            is ill-conditioned); 'auto' refines where that is cheap (small problems) or
%            where W's condition estimate exceeds 1e6 and the cost is moderate.
%          start_branch (positive integer, default 1): where several pieces leave the
%            start point toward alpha1 (res.start_branches), trace piece start_branch,
%          max_alpha_step (alpha units, finite and > 0; default 1/8 of the window): the
%            largest step of a load function's step control. A feature of the load
%            narrower than the steps (a bump, a fast oscillation) can be stepped over
%            unseen; steps no longer than the narrowest feature cannot miss it. No
%            effect on an affine load, whose pieces are followed exactly.
%          monitor (function handle): stop = monitor(alpha, transitions, first_event,
%            last_event), called after each transition point with its alpha, the
%            number of transition points so far and the new events
%            res.events(first_event:last_event). It returns true to stop the path
%            (end_reason 'stopped'; FRICONT_RESUME continues it) or false to go on (1
%            and 0 are accepted too, any other value is an error); a function without
%            output arguments never stops it. An error raised in it stops the path
%            and is rethrown by fricont_trace as it is. Like a load function it runs
%            between library calls, in MATLAB, and must not call into this path
%            (fricont_resume or fricont_solutions_at on its result): that is an error.
%          Any other field is an error (a misspelt option is never ignored).
%
%   res    struct (name it anything but "path", MATLAB's search-path function):
%     events  struct array, one per node changing class, in order: index, transition,
%             alpha, node (contact nodes count from 1), from, to ('open', 'stick',
%             'slip+', 'slip-'), fold, bifurcation, residual, and the state after it:
%             u (n-by-1), lambda_n, lambda_t (p-by-1, lambda_n <= 0 compressive),
%             classes (p-by-1 cell of names).
%     pieces  struct array: alpha_from, alpha_to, direction, orientation, det_sign,
%             classes.
%     start   the start point (alpha, residual, u, lambda_n, lambda_t, classes).
%     start_route  how the start point was reached: 'solved' (the fixed-alpha solver),
%             or, where it failed, 'zero_load' (the path of tau * f(alpha) from
%             tau = 0), 'open' (the path from a load that holds every node open) or,
%             where those failed too, 'nearby' (a path from a nearby alpha); see
%             fricont_path_start in fricont.h.
%     end_reason  'window', 'max_steps', 'closed_loop', 'bifurcation', 'failed' or
%             'stopped' (by the monitor).
%     branches  struct array (classes, direction, orientation_preserving): where the
%             path stopped at a bifurcation (end_reason 'bifurcation'), the pieces that
%             continue it; FRICONT_CHOOSE_BRANCH follows one. Empty otherwise.
%     start_branches  the same for the pieces that left the start point toward
%             alpha1, where more than one did (empty otherwise).
%     extended_precision, w_condition_estimate  whether the trace was in extended
%             precision, and the estimate of the 2-norm condition number of the
%             equilibrated W (in double, transition points can move by up to about
%             50 * w_condition_estimate * 1.1e-16 relative to max(1, |alpha|)).
%     n, p, r, window, and handle/load (used by fricont_solutions_at; the library path
%     is freed when the last copy of the struct is cleared).
%
%   See also FRICONT_SOLUTIONS_AT, FRICONT_RESUME, FRICONT_CHOOSE_BRANCH.
  if nargin < 7
    error('fricont:argument', 'fricont_trace: needs A, N, T, f0, f1, F and the window');
  end
  if nargin < 8 || isempty(opts)
    opts = struct();
  end
  if ~isstruct(opts) || ~isscalar(opts)
    error('fricont:argument', 'fricont_trace: opts must be a scalar struct');
  end
  valid = {'gap', 'r', 'storage', 'max_steps', 'zero_tol', 'guess', 'max_alpha_step', ...
           'monitor', 'start_branch', 'extended_precision'};
  unknown = setdiff(fieldnames(opts), valid);
  if ~isempty(unknown)
    error('fricont:argument', 'fricont_trace: unknown option ''%s''; the options are: %s', ...
          strjoin(unknown(:).', ''', '''), strjoin(valid, ', '));
  end
  if ~isnumeric(window) || numel(window) ~= 2
    error('fricont:argument', 'fricont_trace: the window is [alpha_start alpha_end]');
  end
  monitor = [];
  if isfield(opts, 'monitor')
    monitor = opts.monitor;
    if ~isempty(monitor) && ~isa(monitor, 'function_handle')
      error('fricont:argument', 'fricont_trace: opts.monitor must be a function handle or []');
    end
  end
  start_branch = 1;
  if isfield(opts, 'start_branch')
    start_branch = opts.start_branch;
    if ~isnumeric(start_branch) || ~isreal(start_branch) || ~isscalar(start_branch) || ...
        start_branch < 1 || start_branch ~= fix(start_branch)
      error('fricont:argument', 'fricont_trace: opts.start_branch must be a positive integer');
    end
  end
  storage = 'full';
  if isfield(opts, 'storage')
    storage = opts.storage;
  end

  prob = fricont_mex('problem_new', as_sparse(A, 'A'), storage, as_sparse(N, 'N').', ...
                     as_sparse(T, 'T').');
  free_problem = onCleanup(@() fricont_mex('free', prob));
  fricont_mex('problem_set', prob, 'friction', full(double(F(:))));
  if isfield(opts, 'gap')
    fricont_mex('problem_set', prob, 'gap', full(double(opts.gap(:))));
  end
  if isfield(opts, 'r')
    fricont_mex('problem_set', prob, 'r', double(opts.r));
  end
  if isfield(opts, 'extended_precision')
    mode = find(strcmp(opts.extended_precision, {'auto', 'on', 'off'}));
    if ~ischar(opts.extended_precision) || isempty(mode)
      error('fricont:argument', ['fricont_trace: opts.extended_precision must be ' ...
            '''auto'', ''on'' or ''off''']);
    end
    fricont_mex('problem_set', prob, 'extended', mode - 1);
  end
  [extended, kappa] = fricont_mex('problem_precision', prob);
  r = fricont_mex('problem_r', prob);
  n = size(A, 1);

  if isnumeric(f0) && isa(f1, 'function_handle')
    if ndims(f0) ~= 2 || size(f0, 1) ~= size(A, 1) || size(f0, 2) < 1 || ~isreal(f0)
      error('fricont:argument', ['fricont_trace: the basis vectors V must be a real ' ...
            'n-by-k matrix (n = %d)'], size(A, 1));
    end
    load = struct('w', f1, 'k', size(f0, 2));
    id = fricont_mex('path_new_basis', prob, full(double(f0)));
  elseif isa(f0, 'function_handle')
    if ~isempty(f1) && ~isa(f1, 'function_handle')
      error('fricont:argument', 'fricont_trace: with a load function, df is a function handle or []');
    end
    load = struct('f', f0, 'df', f1);
    id = fricont_mex('path_new_general', prob, double(~isempty(f1)));
  else
    load = [];
    id = fricont_mex('path_new_affine', prob, full(double(f0(:))), full(double(f1(:))));
  end
  handle = fricont_handle(id);
  clear free_problem;                 % the path keeps what it needs

  fricont_mex('path_set', id, 'window', double(window(:).'));
  if isfield(opts, 'max_steps')
    fricont_mex('path_set', id, 'max_steps', double(opts.max_steps));
  end
  if isfield(opts, 'zero_tol')
    fricont_mex('path_set', id, 'zero_tol', double(opts.zero_tol));
  end
  if isfield(opts, 'max_alpha_step')
    h = opts.max_alpha_step;
    if ~isnumeric(h) || ~isreal(h) || ~isscalar(h)
      error('fricont:argument', 'fricont_trace: max_alpha_step must be a real scalar');
    end
    fricont_mex('path_set', id, 'max_alpha_step', double(h));
  end
  guess = [];
  if isfield(opts, 'guess')
    guess = full(double(opts.guess(:)));
  end
  fricont_drive(id, load, n, 'start', double(window(1)), guess);
  start_branches = fricont_mex('branches', id);
  if start_branch > max(numel(start_branches), 1)
    error('fricont:argument', ['fricont_trace: opts.start_branch = %d, but %d piece(s) ' ...
          'leave the start point toward alpha1'], start_branch, max(numel(start_branches), 1));
  end
  if start_branch > 1
    fricont_drive(id, load, n, 'choose_branch', double(start_branch));
  end
  fricont_drive(id, load, n, 'run', monitor);

  res = fricont_mex('path_result', id);
  res.start_branches = start_branches;
  res.extended_precision = extended;
  res.w_condition_estimate = kappa;
  res.r = r;
  res.window = double(window(:).');
  res.handle = handle;
  res.load = load;
end

function S = as_sparse(M, name)
  if ~isnumeric(M) || ~isreal(M) || ndims(M) ~= 2
    error('fricont:argument', 'fricont_trace: %s must be a real matrix', name);
  end
  S = sparse(double(M));
end
