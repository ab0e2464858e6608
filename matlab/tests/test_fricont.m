function failures = test_fricont(case_dir, out_dir)
%TEST_FRICONT Tests of the MATLAB/Octave binding on a problem in the exchange format.
%   Writes the traced events to out_dir/{affine,handle,handle_nodf,lower}.txt (compared
%   with the C interface's by matlab/run.sh) and prints "ok NAME" / "FAIL NAME: why".
  failures = 0;
  confirm_recursive_rmdir(false, 'local');      % rmdir(d, 's') without asking (Octave)
  c = fricont_read_case(case_dir);
  n = size(c.A, 1);
  p = size(c.N, 1);
  opts = struct('gap', c.gap);
  win = [c.alpha_start c.alpha_end];

  % 1. Affine load.
  res = fricont_trace(c.A, c.N, c.T, c.f0, c.f1, c.F, win, opts);
  write_events(fullfile(out_dir, 'affine.txt'), res, @(a) a);
  failures = failures + check('affine: ends at the window', strcmp(res.end_reason, 'window'));
  failures = failures + check('affine: the fixed-alpha solver found the start', ...
                              strcmp(res.start_route, 'solved'));
  failures = failures + check('affine: pieces = events + 1', numel(res.pieces) == numel(res.events) + 1);
  failures = failures + check('handle locks the MEX file', fricont_mex('is_locked'));
  ev = res.events;

  % 2. Solutions between the first two events satisfy the equations (checked here).
  alpha = (ev(1).alpha + ev(2).alpha) / 2;
  S = fricont_solutions_at(res, alpha);
  failures = failures + check('solutions_at: one solution on piece 2', numel(S) == 1 && S(1).piece == 2);
  f = c.f0 + alpha * c.f1;
  [ok, why] = check_solution(c, S(1), f);
  failures = failures + check('solutions_at: equilibrium and contact conditions', ok, why);
  [ok, why] = check_solution(c, ev(1), c.f0 + ev(1).alpha * c.f1);
  failures = failures + check('event state: equilibrium and contact conditions', ok, why);
  failures = failures + check('solutions_at: none outside the traced range', ...
                    isempty(fricont_solutions_at(res, c.alpha_end + 1)));

  % 3. A load given as a function handle, f(s) = f0 + sinh(s) f1, with and without
  %    its derivative: the events are at asinh of the affine ones.
  swin = asinh(win);
  ph = fricont_trace(c.A, c.N, c.T, @(s) c.f0 + sinh(s) * c.f1, @(s) cosh(s) * c.f1, ...
                     c.F, swin, opts);
  write_events(fullfile(out_dir, 'handle.txt'), ph, @sinh);
  ph2 = fricont_trace(c.A, c.N, c.T, @(s) c.f0 + sinh(s) * c.f1, [], c.F, swin, opts);
  write_events(fullfile(out_dir, 'handle_nodf.txt'), ph2, @sinh);
  Sh = fricont_solutions_at(ph, asinh(alpha));
  failures = failures + check('solutions_at through a load function: same u', numel(Sh) == 1 && ...
                    norm(Sh(1).u - S(1).u, inf) <= 1e-8 * norm(S(1).u, inf));

  %    The same as a basis load, V = [f0 f1] with weights [1 0; sinh(s) cosh(s)]: the
  %    events at asinh of the affine ones too; weights of the wrong shape are an error
  %    naming it.
  pbas = fricont_trace(c.A, c.N, c.T, [c.f0 c.f1], @(s) [1 0; sinh(s) cosh(s)], c.F, swin, opts);
  failures = failures + check('basis load f0 + sinh(s) f1: the affine events at asinh', ...
                    strcmp(pbas.end_reason, 'window') && numel(pbas.events) == numel(ev) && ...
                    isequal([pbas.events.node], [ev.node]) && isequal({pbas.events.to}, {ev.to}) && ...
                    max(abs(sinh([pbas.events.alpha]) - [ev.alpha]) ./ max(1, abs([ev.alpha]))) <= 1e-9);
  [ident, msg] = caught(@() fricont_trace(c.A, c.N, c.T, [c.f0 c.f1], @(s) [1; s], c.F, swin, opts));
  failures = failures + check('basis weights not k-by-2: fricont:load naming it', ...
                    strcmp(ident, 'fricont:load') && ~isempty(strfind(msg, 'k-by-2')), [ident ' ' msg]);
  clear pbas;

  %    Extended precision: the sample is small, so auto refines it; off traces it in
  %    double, to the same events. The one-node block A = diag(2, 1), N = [1 0],
  %    T = [0 1] has W = diag(1/2, 1): condition 2.
  failures = failures + check('extended precision: auto refines the sample', ...
                    res.extended_precision && res.w_condition_estimate > 1);
  poff = fricont_trace(c.A, c.N, c.T, c.f0, c.f1, c.F, win, ...
                       struct('gap', c.gap, 'extended_precision', 'off'));
  failures = failures + check('extended precision off: in double, the same events', ...
                    ~poff.extended_precision && numel(poff.events) == numel(ev) && ...
                    isequal([poff.events.node], [ev.node]) && ...
                    max(abs([poff.events.alpha] - [ev.alpha])) <= 1e-10);
  blk = fricont_trace(sparse([2 0; 0 1]), sparse([1 0]), sparse([0 1]), [1; 0], [0; 1], 0.5, [0 1]);
  failures = failures + check('W = diag(1/2, 1): condition estimate 2', ...
                    abs(blk.w_condition_estimate - 2) <= 1e-9, sprintf('%.17g', blk.w_condition_estimate));
  [ident, msg] = caught(@() fricont_trace(c.A, c.N, c.T, c.f0, c.f1, c.F, win, ...
                                          struct('extended_precision', 'yes')));
  failures = failures + check('extended precision ''yes'': fricont:argument', ...
                    strcmp(ident, 'fricont:argument'), [ident ' ' msg]);
  clear poff blk;

  % 4. The lower triangle of A with storage 'lower' gives the same path as the full
  %    matrix with the same entries (A.mtx need not be bit-symmetric, and a shallow
  %    crossing can amplify a last-bit difference between the triangles well above 1e-12).
  Al = tril(c.A);
  pl = fricont_trace(Al, c.N, c.T, c.f0, c.f1, c.F, win, ...
                     struct('gap', c.gap, 'storage', 'lower'));
  write_events(fullfile(out_dir, 'lower.txt'), pl, @(a) a);
  ps = fricont_trace(Al + tril(Al, -1).', c.N, c.T, c.f0, c.f1, c.F, win, opts);
  write_events(fullfile(out_dir, 'full_of_lower.txt'), ps, @(a) a);

  % 5. An error in the load function: raised by fricont_trace, after the library call
  %    returned; nothing is left allocated.
  clear res ph ph2 pl ps;
  failures = failures + check('every handle freed when the structs are cleared', fricont_mex('count') == 0);
  failures = failures + check('MEX file unlocked without handles', ~fricont_mex('is_locked'));
  stop = (ev(2).alpha + ev(3).alpha) / 2;
  msg = '';
  try
    fricont_trace(c.A, c.N, c.T, @(a) failing_load(a, stop, c), [], c.F, win, opts);
  catch err
    msg = err.message;
    ident = err.identifier;
  end
  failures = failures + check('load function error: raised as fricont:load', ...
                    ~isempty(msg) && strcmp(ident, 'fricont:load') && ...
                    ~isempty(strfind(msg, 'load not defined past the stop')), msg);
  failures = failures + check('load function error: nothing left allocated', fricont_mex('count') == 0);
  msg = '';
  try
    fricont_trace(c.A, c.N, c.T, @(a) ones(3, 1), [], c.F, win, opts);
  catch err
    msg = err.message;
  end
  failures = failures + check('load function of the wrong length: clear error', ...
                    ~isempty(strfind(msg, 'real vector of n = ')), msg);

  % 6. Bad input: library errors with their status as identifier.
  ident = '';
  try
    fricont_trace(c.A, c.N(:, 1:end-1), c.T, c.f0, c.f1, c.F, win, opts);
  catch err
    ident = err.identifier;
    msg = err.message;
  end
  failures = failures + check('N with a wrong column count: fricont:ERR_LENGTH', ...
                    strcmp(ident, 'fricont:ERR_LENGTH'), [ident ' ' msg]);
  ident = '';
  try
    fricont_trace(c.A, c.N, c.T, c.f0, c.f1, -1, win, opts);
  catch err
    ident = err.identifier;
  end
  failures = failures + check('negative friction: fricont:ERR_RANGE', strcmp(ident, 'fricont:ERR_RANGE'), ident);
  ident = '';
  try
    fricont_mex('path_result', uint64(123456));
  catch err
    ident = err.identifier;
  end
  failures = failures + check('unknown handle: fricont:handle', strcmp(ident, 'fricont:handle'), ident);
  ident = '';
  try
    fricont_mex('path_result', 3);
  catch err
    ident = err.identifier;
  end
  failures = failures + check('handle of the wrong class: fricont:handle', strcmp(ident, 'fricont:handle'), ident);

  % 7. Options and messages: a misspelt option field is an error naming it and the
  %    valid ones; messages read "fricont: <the library's message>", without the MEX
  %    file's name (Octave's mexErrMsgIdAndTxt adds it) or the request's tag.
  [ident, msg] = caught(@() fricont_trace(c.A, c.N, c.T, c.f0, c.f1, c.F, win, struct('gapp', c.gap)));
  failures = failures + check('unknown option field: an error naming it and the valid ones', ...
                    strcmp(ident, 'fricont:argument') && ~isempty(strfind(msg, '''gapp''')) && ...
                    ~isempty(strfind(msg, 'gap, r, storage, max_steps, zero_tol, guess')), msg);
  An = c.A;
  An(1, 2) = An(1, 2) + 1;
  [ident, msg] = caught(@() fricont_trace(An, c.N, c.T, c.f0, c.f1, c.F, win, opts));
  failures = failures + check('non-symmetric A: "fricont: A is not symmetric: A(1, 2) ..."', ...
                    strcmp(ident, 'fricont:ERR_NOT_SYMMETRIC') && ...
                    strncmp(msg, 'fricont: A is not symmetric: A(1, 2) and A(2, 1)', 48), msg);
  [ident, msg] = caught(@() fricont_trace(c.A, c.N, c.T, c.f0, c.f1, c.F, win, struct('r', -1)));
  failures = failures + check('r = -1: "fricont: r = -1, must be ..."', ...
                    strcmp(ident, 'fricont:ERR_RANGE') && strncmp(msg, 'fricont: r = -1, must be', 24), msg);
  [ident, msg] = caught(@() fricont_mex('path_result', 3));
  failures = failures + check('MEX argument error: "fricont: a handle must be a uint64 scalar"', ...
                    strcmp(msg, 'fricont: a handle must be a uint64 scalar'), [ident ' ' msg]);
  failures = failures + check('every handle freed after the errors', fricont_mex('count') == 0);

  % 8. fricont_read_case: other Matrix Market forms of the same matrices read the same
  %    (N as a dense 'array', A as the lower triangle of a 'symmetric' file with integer
  %    indices written by hand here); 'pattern' is a clear error naming the file.
  d = tempname();
  mkdir(d);
  for f = {'A.mtx', 'T.mtx', 'f0.txt', 'f1.txt', 'gap.txt', 'meta.json'}
    copyfile(fullfile(case_dir, f{1}), fullfile(d, f{1}));
  end
  fid = fopen(fullfile(d, 'N.mtx'), 'w');
  fprintf(fid, '%%%%MatrixMarket matrix array real general\n%% dense, column by column\n%d %d\n', p, n);
  fprintf(fid, '%.17g\n', full(c.N));
  fclose(fid);
  [i, j, v] = find(tril(c.A));
  fid = fopen(fullfile(d, 'A.mtx'), 'w');
  fprintf(fid, '%%%%MatrixMarket matrix coordinate real symmetric\n%d %d %d\n', n, n, numel(v));
  fprintf(fid, '%d %d %.17g\n', [i j v].');
  fclose(fid);
  c2 = fricont_read_case(d);
  failures = failures + check('read_case: array N and symmetric A equal the coordinate files', ...
                    isequal(c2.N, c.N) && isequal(c2.A, tril(c.A) + tril(c.A, -1).'));
  fid = fopen(fullfile(d, 'T.mtx'), 'w');
  fprintf(fid, '%%%%MatrixMarket matrix coordinate pattern general\n%d %d 1\n1 1\n', p, n);
  fclose(fid);
  [ident, msg] = caught(@() fricont_read_case(d));
  failures = failures + check('read_case: a pattern file is an error naming the file', ...
                    strcmp(ident, 'fricont:read') && ~isempty(strfind(msg, fullfile(d, 'T.mtx'))) && ...
                    ~isempty(strfind(msg, 'pattern')), msg);
  rmdir(d, 's');

  % 9. fricont_build names what is missing and what to do: a repository without a
  %    built library, a directory that is neither.
  d = tempname();
  mkdir(fullfile(d, 'include'));
  fclose(fopen(fullfile(d, 'Cargo.toml'), 'w'));
  fclose(fopen(fullfile(d, 'include', 'fricont.h'), 'w'));
  [ident, msg] = caught(@() fricont_build(d, d));
  failures = failures + check('fricont_build: a repository without target/release/libfricont.so', ...
                    strcmp(ident, 'fricont:build') && ~isempty(strfind(msg, 'libfricont.so not found')) && ...
                    ~isempty(strfind(msg, 'cargo build --release')), msg);
  [ident, msg] = caught(@() fricont_build(fullfile(d, 'nothing-here')));
  failures = failures + check('fricont_build: not a directory', ...
                    strcmp(ident, 'fricont:build') && ~isempty(strfind(msg, 'is not a directory')), msg);
  rmdir(d, 's');

  % 10. A request MATLAB abandons (as after Ctrl-C) does not hang or leak: freeing the
  %    handle ends the pending library call.
  prob = fricont_mex('problem_new', c.A, 'full', c.N.', c.T.');
  fricont_mex('problem_set', prob, 'friction', c.F);
  id = fricont_mex('path_new_general', prob, 0);
  fricont_mex('free', prob);
  fricont_mex('path_set', id, 'window', win);
  [what, value] = fricont_mex('path_call', id, 'start', win(1), []);
  failures = failures + check('a load request reaches MATLAB', strcmp(what, 'f') && value == win(1), what);
  fricont_mex('free', id);
  failures = failures + check('abandoned request: handle freed', fricont_mex('count') == 0);

  % 11. A monitor that stops the path after 3 transition points: end reason 'stopped',
  %    the events so far are the first events of the unmonitored run (section 1, the
  %    same arithmetic: equal bits); each call gets the alpha, the count and the range
  %    (from 1) of the new events. fricont_resume runs it on to the unmonitored run's
  %    end and events.
  calls = zeros(0, 4);
  function stop = stop_at_3(a, t, first, last)
    calls(end + 1, :) = [a t first last];
    stop = t >= 3;
  end
  opts_m = opts;
  opts_m.monitor = @stop_at_3;
  ms = fricont_trace(c.A, c.N, c.T, c.f0, c.f1, c.F, win, opts_m);
  failures = failures + check('monitor: true ends the path as ''stopped''', ...
                    strcmp(ms.end_reason, 'stopped'), ms.end_reason);
  failures = failures + check('monitor: called after transition points 1, 2, 3', ...
                    isequal(calls(:, 2).', 1:3), mat2str(calls));
  ok = ~isempty(calls) && calls(1, 3) == 1 && all(calls(2:end, 3) == calls(1:end-1, 4) + 1) && ...
       all(calls(:, 4) >= calls(:, 3)) && numel(ms.events) == calls(end, 4);
  for k = 1:size(calls, 1)
    for j = calls(k, 3):min(calls(k, 4), numel(ev))
      ok = ok && ev(j).alpha == calls(k, 1) && ev(j).transition == calls(k, 2);
    end
  end
  failures = failures + check('monitor: its events are res.events(first:last), at its alpha', ok, ...
                    mat2str(calls, 17));
  failures = failures + check('monitor: the events so far are the first of the unmonitored run', ...
                    same_events(ms.events, ev(1:min(end, numel(ms.events)))) && ...
                    numel(ms.events) < numel(ev));
  calls = zeros(0, 4);
  ms2 = fricont_resume(ms, @stop_at_3);          % true from transition 3 on: stops at 4
  failures = failures + check('fricont_resume with a monitor: stops at the next transition point', ...
                    strcmp(ms2.end_reason, 'stopped') && isequal(calls(:, 2).', 4) && ...
                    same_events(ms2.events, ev(1:calls(end, 4))), mat2str(calls));
  ms2 = fricont_resume(ms2);
  failures = failures + check('fricont_resume: the unmonitored run''s end and events', ...
                    strcmp(ms2.end_reason, 'window') && same_events(ms2.events, ev) && ...
                    numel(ms2.pieces) == numel(ev) + 1, ms2.end_reason);
  failures = failures + check('fricont_resume of an ended path: unchanged', ...
                    same_events(getfield(fricont_resume(ms2), 'events'), ev));
  failures = failures + check('the stopped struct keeps its events, shares the path', ...
                    numel(ms.events) == 3 && ...
                    ~isempty(fricont_solutions_at(ms, (ev(end).alpha + c.alpha_end) / 2)));
  % A load function and a monitor in one run (both answered by MATLAB).
  calls = zeros(0, 4);
  opts_h = opts_m;
  mh = fricont_trace(c.A, c.N, c.T, @(s) c.f0 + sinh(s) * c.f1, [], c.F, asinh(win), opts_h);
  failures = failures + check('monitor with a load function: stops after 3, at asinh of the events', ...
                    strcmp(mh.end_reason, 'stopped') && numel(mh.events) == 3 && ...
                    max(abs(sinh([mh.events.alpha]) - [ev(1:3).alpha])) <= 1e-9 && ...
                    isequal(calls(:, 2).', 1:3));
  % A function without output arguments only watches; 1 and 0 are accepted.
  counted = 0;
  function watch(a, t, first, last)
    counted = t;
  end
  opts_m.monitor = @watch;
  mw = fricont_trace(c.A, c.N, c.T, c.f0, c.f1, c.F, win, opts_m);
  failures = failures + check('monitor without output: never stops, sees every transition point', ...
                    strcmp(mw.end_reason, 'window') && counted == ev(end).transition);
  opts_m.monitor = @(a, t, first, last) double(t == 2);
  mw = fricont_trace(c.A, c.N, c.T, c.f0, c.f1, c.F, win, opts_m);
  failures = failures + check('monitor returning 1: stops', strcmp(mw.end_reason, 'stopped') && ...
                    mw.events(end).transition == 2);
  clear ms ms2 mh mw;
  failures = failures + check('monitored paths freed when the structs are cleared', fricont_mex('count') == 0);

  % 12. An error in the monitor stops the path and reaches the caller as it was raised;
  %    nothing is left allocated. Other values than true/false/1/0 are an error; a
  %    monitor that calls into its own path gets a clear error (not an abandoned run).
  opts_m.monitor = @(a, t, first, last) monitor_fails(t);
  [ident, msg] = caught(@() fricont_trace(c.A, c.N, c.T, c.f0, c.f1, c.F, win, opts_m));
  failures = failures + check('monitor error: raised with its identifier and message', ...
                    strcmp(ident, 'test:monitor') && strcmp(msg, 'monitor gives up at transition 2'), ...
                    [ident ' ' msg]);
  failures = failures + check('monitor error: nothing left allocated', fricont_mex('count') == 0);
  [ident, msg] = caught(@() fricont_trace(c.A, c.N, c.T, @(s) c.f0 + s * c.f1, [], c.F, win, opts_m));
  failures = failures + check('monitor error with a load function: raised, nothing left allocated', ...
                    strcmp(ident, 'test:monitor') && fricont_mex('count') == 0, [ident ' ' msg]);
  opts_m.monitor = @(a, t, first, last) 2;
  [ident, msg] = caught(@() fricont_trace(c.A, c.N, c.T, c.f0, c.f1, c.F, win, opts_m));
  failures = failures + check('monitor returning 2: an error saying what it must return', ...
                    strcmp(ident, 'fricont:monitor') && ~isempty(strfind(msg, 'true (stop) or false')), msg);
  opts_m.monitor = 'stop';
  [ident, msg] = caught(@() fricont_trace(c.A, c.N, c.T, c.f0, c.f1, c.F, win, opts_m));
  failures = failures + check('opts.monitor not a function: fricont:argument', ...
                    strcmp(ident, 'fricont:argument') && ~isempty(strfind(msg, 'monitor')), msg);
  opts_m.monitor = @(a, t, first, last) t >= 1;
  ms = fricont_trace(c.A, c.N, c.T, c.f0, c.f1, c.F, win, opts_m);
  [ident, msg] = caught(@() fricont_resume(ms, @(a, t, first, last) isempty(fricont_solutions_at(ms, a))));
  failures = failures + check('monitor calling into its own path: fricont:order, the path stopped', ...
                    strcmp(ident, 'fricont:order') && ~isempty(strfind(msg, 'in use')) && ...
                    same_events(getfield(fricont_mex('path_result', ms.handle.id), 'events'), ...
                                ev(1:find([ev.transition] == 2, 1, 'last'))), [ident ' ' msg]);
  clear ms;
  % A monitor request MATLAB leaves unanswered (Ctrl-C in the monitor: fricont_drive's
  % onCleanup then calls 'settle'): the path is in use until then, and stopped after.
  prob = fricont_mex('problem_new', c.A, 'full', c.N.', c.T.');
  fricont_mex('problem_set', prob, 'friction', c.F);
  fricont_mex('problem_set', prob, 'gap', c.gap);
  id = fricont_mex('path_new_affine', prob, c.f0, c.f1);
  fricont_mex('free', prob);
  fricont_mex('path_set', id, 'window', win);
  fricont_mex('path_call', id, 'start', win(1), []);
  [what, value] = fricont_mex('path_call', id, 'run', 1);
  k1 = sum([ev.transition] == 1);
  failures = failures + check('a monitor request reaches MATLAB: [alpha 1 1 last]', ...
                    strcmp(what, 'monitor') && isequal(value, [ev(1).alpha 1 1 k1]), mat2str(value, 17));
  ident = caught(@() fricont_mex('path_result', id));
  failures = failures + check('while it is pending the path is in use', strcmp(ident, 'fricont:order'), ident);
  fricont_mex('settle', id);
  r = fricont_mex('path_result', id);
  failures = failures + check('settled: the run stopped after the first transition point', ...
                    strcmp(r.end_reason, 'stopped') && same_events(r.events, ev(1:k1)), r.end_reason);
  fricont_mex('free', id);
  failures = failures + check('every handle freed after the monitor errors', fricont_mex('count') == 0);

  % 13. max_alpha_step: one node, A = I, N = [1 0], T = [0 1], F = 0.3, normal load
  %    0.5 - 0.6 exp(-((alpha - ab)/w)^2): the node opens where the exponential exceeds
  %    5/6, i.e. for |alpha - ab| < w sqrt(log(1.2)) (by hand). Steps of at most 1e-3
  %    find both transitions there; the default steps (up to 1/8 of the window) never
  %    evaluate the load on the bump. Bad values are errors for every kind of load.
  ab = 21.5 / 64;
  w = 2e-3;
  half = w * sqrt(log(1.2));
  bump = @(a) [0.5 - 0.6 * exp(-((a - ab) / w)^2); 0];
  A1 = speye(2);
  N1 = sparse([1 0]);
  T1 = sparse([0 1]);
  pb = fricont_trace(A1, N1, T1, bump, [], 0.3, [-1 1], struct('max_alpha_step', 1e-3));
  ok = strcmp(pb.end_reason, 'window') && numel(pb.events) == 2;
  if ok
    ok = strcmp(pb.events(1).from, 'stick') && strcmp(pb.events(1).to, 'open') && ...
         strcmp(pb.events(2).from, 'open') && strcmp(pb.events(2).to, 'stick') && ...
         all([pb.events.node] == 1) && abs(pb.events(1).alpha - (ab - half)) <= 1e-10 && ...
         abs(pb.events(2).alpha - (ab + half)) <= 1e-10;
  end
  failures = failures + check('max_alpha_step 1e-3: the bump''s two transitions at ab -/+ w sqrt(log 1.2)', ...
                    ok, sprintf('%s, alphas %s', pb.end_reason, mat2str([pb.events.alpha], 15)));
  pd = fricont_trace(A1, N1, T1, bump, [], 0.3, [-1 1]);
  failures = failures + check('default steps: the bump is stepped over (so the option took effect)', ...
                    isempty(pd.events));
  bad = {0, -1, NaN, Inf};
  ok = true;
  why = '';
  for k = 1:numel(bad)
    for kind = {'function', 'affine'}
      if strcmp(kind{1}, 'function')
        [ident, msg] = caught(@() fricont_trace(A1, N1, T1, bump, [], 0.3, [-1 1], ...
                                                struct('max_alpha_step', bad{k})));
      else
        [ident, msg] = caught(@() fricont_trace(A1, N1, T1, [0.5; 0], [0; 0], 0.3, [-1 1], ...
                                                struct('max_alpha_step', bad{k})));
      end
      if ~strcmp(ident, 'fricont:ERR_RANGE') || isempty(strfind(msg, 'max_alpha_step'))
        ok = false;
        why = [why sprintf('%g (%s): %s %s; ', bad{k}, kind{1}, ident, msg)];
      end
    end
  end
  failures = failures + check('max_alpha_step 0, -1, NaN, Inf: fricont:ERR_RANGE naming it', ok, why);
  [ident, msg] = caught(@() fricont_trace(A1, N1, T1, bump, [], 0.3, [-1 1], ...
                                          struct('max_alpha_step', [1e-3 1e-2])));
  failures = failures + check('max_alpha_step not a scalar: fricont:argument naming it', ...
                    strcmp(ident, 'fricont:argument') && ~isempty(strfind(msg, 'max_alpha_step')), msg);
  clear pb pd;
  failures = failures + check('every handle freed after the max_alpha_step cases', fricont_mex('count') == 0);

  % 8. Bifurcations. tests/data/bifurcation-stop (a mirror-symmetric pair) stops at a
  %    bifurcation with three candidates (python/tests checks them against a brute-force
  %    enumeration): fricont_choose_branch(res, k) follows candidate k to the window's end,
  %    keeping the events before it, with states that satisfy the equations (checked here).
  data = fileparts(case_dir);
  b = fricont_read_case(fullfile(data, 'bifurcation-stop'));
  bwin = [b.alpha_start b.alpha_end];
  stop = fricont_trace(b.A, b.N, b.T, b.f0, b.f1, b.F, bwin, struct('gap', b.gap));
  failures = failures + check('bifurcation: the path stops with three candidates', ...
                    strcmp(stop.end_reason, 'bifurcation') && numel(stop.branches) == 3 && ...
                    isempty(stop.start_branches));
  np = numel(stop.pieces);
  ok = true;
  why = '';
  for k = 1:numel(stop.branches)
    other = fricont_trace(b.A, b.N, b.T, b.f0, b.f1, b.F, bwin, struct('gap', b.gap));
    other = fricont_choose_branch(other, k);
    ne = numel(stop.events);
    if ~strcmp(other.end_reason, 'window') || ~isempty(other.branches) || ...
        ~same_events(other.events(1:ne), stop.events) || ...
        ~isequal(other.pieces(np + 1).classes, stop.branches(k).classes) || ...
        other.pieces(np + 1).direction ~= stop.branches(k).direction || ...
        numel(other.events) <= ne || ~other.events(ne + 1).bifurcation
      ok = false;
      why = [why sprintf('branch %d: end %s, %d events; ', k, other.end_reason, numel(other.events))];
    end
    for e = other.events(ne + 1:end).'
      [good, w] = check_solution(b, e, b.f0 + e.alpha * b.f1);
      if ~good
        ok = false;
        why = [why sprintf('branch %d event %d: %s; ', k, e.index, w)];
      end
    end
  end
  failures = failures + check('fricont_choose_branch follows each candidate', ok, why);
  %    The same through a load function (the worker thread runs the choice).
  fh = fricont_trace(b.A, b.N, b.T, @(a) b.f0 + a * b.f1, @(a) b.f1, b.F, bwin, struct('gap', b.gap));
  fh = fricont_choose_branch(fh, numel(stop.branches));
  failures = failures + check('fricont_choose_branch through a load function: the affine events', ...
                    strcmp(fh.end_reason, 'window') && ...
                    isequal({fh.events.to}, {other.events.to}) && ...
                    max(abs([fh.events.alpha] - [other.events.alpha])) <= 1e-9);
  [ident, msg] = caught(@() fricont_choose_branch(stop, 4));
  failures = failures + check('fricont_choose_branch k out of range: fricont:ERR_RANGE', ...
                    strcmp(ident, 'fricont:ERR_RANGE'), [ident ' ' msg]);
  [ident, msg] = caught(@() fricont_choose_branch(other, 1));
  failures = failures + check('fricont_choose_branch after the path moved on: fricont:ERR_ORDER', ...
                    strcmp(ident, 'fricont:ERR_ORDER'), [ident ' ' msg]);
  [ident, msg] = caught(@() fricont_choose_branch(stop, 1.5));
  failures = failures + check('fricont_choose_branch k not an integer: fricont:argument', ...
                    strcmp(ident, 'fricont:argument'), [ident ' ' msg]);

  %    tests/data/vertex-start: three curves leave the start point toward alpha_end (the
  %    brute force of tests/common: (open, slip+), (slip-, slip+), (stick, slip-));
  %    opts.start_branch = k traces the k-th of res.start_branches.
  v = fricont_read_case(fullfile(data, 'vertex-start'));
  vwin = [v.alpha_start v.alpha_end];
  first = fricont_trace(v.A, v.N, v.T, v.f0, v.f1, v.F, vwin, struct('gap', v.gap));
  sb = first.start_branches;
  got = sort(cellfun(@(c) strjoin(c(:).', ','), {sb.classes}, 'UniformOutput', false));
  failures = failures + check('start_branches: the three curves of the brute force', ...
                    isequal(got, {'open,slip+', 'slip-,slip+', 'stick,slip-'}), strjoin(got, '; '));
  ok = true;
  for k = 1:numel(sb)
    r = fricont_trace(v.A, v.N, v.T, v.f0, v.f1, v.F, vwin, struct('gap', v.gap, 'start_branch', k));
    ok = ok && strcmp(r.end_reason, 'window') && isequal(r.pieces(1).classes, sb(k).classes);
  end
  failures = failures + check('opts.start_branch traces each piece leaving the start', ok);
  [ident, msg] = caught(@() fricont_trace(v.A, v.N, v.T, v.f0, v.f1, v.F, vwin, ...
                                          struct('gap', v.gap, 'start_branch', 4)));
  failures = failures + check('opts.start_branch beyond them: fricont:argument', ...
                    strcmp(ident, 'fricont:argument') && ~isempty(strfind(msg, '3 piece(s)')), msg);
  clear stop other first r fh;
  failures = failures + check('every handle freed after the bifurcation cases', fricont_mex('count') == 0);
  fprintf('matlab test_fricont: %d failed check(s)\n', failures);
end

function stop = monitor_fails(t)
  if t == 2
    error('test:monitor', 'monitor gives up at transition %d', t);
  end
  stop = false;
end

% Same alpha (bits), node, classes and transition, event by event.
function same = same_events(a, b)
  same = numel(a) == numel(b) && isequal([a.alpha], [b.alpha]) && isequal([a.node], [b.node]) && ...
         isequal({a.from}, {b.from}) && isequal({a.to}, {b.to}) && ...
         isequal([a.transition], [b.transition]);
end

% The identifier and message of the error fn() raises ('' if none).
function [ident, msg] = caught(fn)
  ident = '';
  msg = '';
  try
    fn();
  catch err
    ident = err.identifier;
    msg = err.message;
  end
end

function f = failing_load(a, stop, c)
  if a > stop
    error('test:stop', 'load not defined past the stop');
  end
  f = c.f0 + a * c.f1;
end

function bad = check(name, cond, why)
  bad = ~cond;
  if cond
    fprintf('ok %s\n', name);
  elseif nargin > 2
    fprintf('FAIL %s: %s\n', name, why);
  else
    fprintf('FAIL %s\n', name);
  end
end

% Equilibrium A u = f + N' lambda_n + T' lambda_t and each node's class conditions.
function [ok, why] = check_solution(c, s, f)
  why = '';
  res = norm(c.A * s.u - f - c.N.' * s.lambda_n - c.T.' * s.lambda_t, inf) / norm(f, inf);
  dn = c.N * s.u - c.gap;
  dt = c.T * s.u;
  tl = 1e-9 * norm(s.u, inf);
  tf = 1e-9 * max(abs([s.lambda_n; s.lambda_t]));
  F = c.F .* ones(size(dn));
  ok = res <= 1e-9;
  if ~ok
    why = sprintf('equilibrium residual %.3g', res);
  end
  for i = 1:numel(dn)
    ln = s.lambda_n(i); lt = s.lambda_t(i);
    good = ln <= tf && dn(i) <= tl && abs(lt) <= -F(i) * ln + tf;
    switch s.classes{i}
      case 'open'
        good = good && abs(ln) <= tf && abs(lt) <= tf;
      case 'stick'
        good = good && abs(dn(i)) <= tl && abs(dt(i)) <= tl;
      case 'slip+'
        good = good && abs(dn(i)) <= tl && abs(lt - F(i) * ln) <= tf && dt(i) >= -tl;
      case 'slip-'
        good = good && abs(dn(i)) <= tl && abs(lt + F(i) * ln) <= tf && dt(i) <= tl;
    end
    if ~good
      ok = false;
      why = sprintf('node %d violates %s', i, s.classes{i});
      return;
    end
  end
end

% The events in the plain text form of tests-install/trace_case.c (alpha mapped).
function write_events(file, res, map)
  fid = fopen(file, 'w');
  fprintf(fid, 'start %.17g %.3e\n', map(res.start.alpha), res.start.residual);
  for e = res.events(:).'
    fprintf(fid, 'event %d %d %.17g %d %s %s %d %d\n', e.index, e.transition, map(e.alpha), ...
            e.node, e.from, e.to, e.fold, e.bifurcation);
  end
  fprintf(fid, 'end %s %d\n', res.end_reason, numel(res.pieces));
  fclose(fid);
end
