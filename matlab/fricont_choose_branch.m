function res = fricont_choose_branch(res, k, monitor)
%FRICONT_CHOOSE_BRANCH Continue a path along another branch of the bifurcation it stopped at.
%
%   res = fricont_choose_branch(res, k)
%   res = fricont_choose_branch(res, k, monitor)
%
%   res      the result of FRICONT_TRACE (or of FRICONT_RESUME or FRICONT_CHOOSE_BRANCH)
%            with end_reason 'bifurcation': res.branches lists the pieces that continue
%            the path there.
%   k        which of them to follow: an integer from 1 to numel(res.branches).
%   monitor  a function handle called as opts.monitor of FRICONT_TRACE, or [] (the
%            default: none).
%
%   The library path is continued along res.branches(k) and run on until it ends again;
%   returns res with events, pieces, branches, end_reason and callback_code updated (the
%   events traced up to the bifurcation are kept, the chosen branch's follow). Only
%   directly after the bifurcation: on a path that has moved on since, or with k out of
%   range, it is an error (fricont:ORDER, fricont:RANGE) and the path is left as it was.
%   As for FRICONT_RESUME, every copy of res shares the library path.
%
%   See also FRICONT_TRACE, FRICONT_RESUME.
  if ~isstruct(res) || ~isscalar(res) || ~isfield(res, 'handle') || ~isa(res.handle, 'fricont_handle')
    error('fricont:argument', 'fricont_choose_branch: res must come from fricont_trace');
  end
  if ~isnumeric(k) || ~isreal(k) || ~isscalar(k) || k < 1 || k ~= fix(k)
    error('fricont:argument', 'fricont_choose_branch: k must be a positive integer');
  end
  if nargin < 3
    monitor = [];
  end
  if ~isempty(monitor) && ~isa(monitor, 'function_handle')
    error('fricont:argument', 'fricont_choose_branch: monitor must be a function handle or []');
  end
  fricont_drive(res.handle.id, res.load, res.n, 'choose_branch', double(k));
  res = fricont_resume(res, monitor);
end
