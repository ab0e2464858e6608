function S = fricont_solutions_at(res, alpha)
%FRICONT_SOLUTIONS_AT Every traced solution at a given load parameter.
%
%   S = fricont_solutions_at(res, alpha)
%
%   res    the result of FRICONT_TRACE.
%   alpha  the load parameter.
%   S      struct array, one element per traced piece whose alpha-range contains alpha
%          (several past a fold, empty if the path never reached alpha): alpha,
%          residual, u, lambda_n, lambda_t, classes, piece (the index into
%          res.pieces) and continuum (true when the piece is vertical: every point
%          between its ends is a solution too). One small solve on the stored piece and
%          one back-solve for u each; a load function is evaluated by MATLAB.
%
%   See also FRICONT_TRACE.
  if ~isstruct(res) || ~isfield(res, 'handle') || ~isa(res.handle, 'fricont_handle')
    error('fricont:argument', 'fricont_solutions_at: res must come from fricont_trace');
  end
  if ~isnumeric(alpha) || ~isscalar(alpha)
    error('fricont:argument', 'fricont_solutions_at: alpha must be a scalar');
  end
  id = res.handle.id;
  [~, count] = fricont_drive(id, res.load, res.n, 'solutions_at', double(alpha));
  S = fricont_mex('solutions', id, count);
end
