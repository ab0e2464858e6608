% TRACE_SAMPLE  A MATLAB/Octave user's script: the sample problem of fricont traced
% from its files.
%
% It reads a problem directory in the exchange format (Matrix Market A.mtx, N.mtx,
% T.mtx, the vectors f0.txt, f1.txt, gap.txt and meta.json; by default the sample
% tests/data/sample-rect30: a Q1 rectangle, n = 1320 dofs, p = 30 contact nodes,
% F = 0.3, alpha in [-0.5, 1.5]), traces the solution path over the window of its
% meta.json and prints every transition point (contact nodes numbered from 1, alpha to 14
% significant digits) and the total normal contact force at each.
%
% From the repository root, after `cargo build --release`:
%   octave-cli --eval "addpath('matlab/examples'); trace_sample"
% Against an installed copy (scripts/install.sh PREFIX), with a problem directory of
% your own (`fricont gen-rect DIR` writes one):
%   addpath PREFIX/share/fricont/matlab/examples; case_dir = 'DIR'; trace_sample
% Call it by name, as here: `run FILE` changes into the script's folder first, and a
% relative case_dir would then name the wrong place. The script puts the binding's
% folder (the parent of this one) on the path and builds the MEX gateway when it is
% missing (fricont_build).
here = fileparts(mfilename('fullpath'));
if ~exist('fricont_trace', 'file')
  addpath(fullfile(here, '..'));
end
if exist('fricont_mex', 'file') ~= 3
  fricont_build();
end
if ~exist('case_dir', 'var')
  case_dir = fullfile(here, '..', '..', 'tests', 'data', 'sample-rect30');
end

c = fricont_read_case(case_dir);      % c.A, c.N, c.T sparse; c.f0, c.f1, c.gap, c.F, window
window = [c.alpha_start c.alpha_end];
res = fricont_trace(c.A, c.N, c.T, c.f0, c.f1, c.F, window, struct('gap', c.gap));

fprintf('%s: n = %d dofs, p = %d contact nodes, alpha from %g to %g\n', case_dir, ...
        size(c.A, 1), size(c.N, 1), window(1), window(2));
fprintf('start at alpha = %g:%s\n\n', res.start.alpha, sprintf(' %s', res.start.classes{:}));
% Each event carries the state after it: u, lambda_n (<= 0 compressive), lambda_t, classes.
fprintf('  #  alpha              node  from   -> to      sum(lambda_n)  flags\n');
for k = 1:numel(res.events)
  e = res.events(k);
  flags = '';
  if e.fold, flags = [flags ' fold']; end
  if e.bifurcation, flags = [flags ' bifurcation']; end
  fprintf('%3d  %-17.14g  %4d  %-6s -> %-6s  %13.6e %s\n', k, e.alpha, e.node, e.from, e.to, ...
          sum(e.lambda_n), flags);
end
fprintf('\n%d events, the path ends: %s\n', numel(res.events), res.end_reason);

