function res = fricont_resume(res, monitor)
%FRICONT_RESUME Continue a path that its monitor stopped.
%
%   res = fricont_resume(res)
%   res = fricont_resume(res, monitor)
%
%   res      the result of FRICONT_TRACE (or of FRICONT_RESUME) with end_reason
%            'stopped': the library path it holds is run on from where it stopped until
%            it ends again. The events then equal those of a run that was never stopped.
%            A path that ended for another reason is left as it is.
%   monitor  a function handle called as opts.monitor of FRICONT_TRACE, or [] (the
%            default: none; the monitor given to fricont_trace is not kept).
%
%   Returns res with events, pieces, end_reason and callback_code updated. The struct
%   passed in and every copy of it share the library path: fricont_solutions_at on any
%   of them sees the whole path, but their events stay as they were. An error raised by
%   the monitor stops the path again and is rethrown (the path stays usable: call
%   fricont_resume again); an error of a load function ends it ('failed').
%
%   See also FRICONT_TRACE, FRICONT_SOLUTIONS_AT.
  if ~isstruct(res) || ~isscalar(res) || ~isfield(res, 'handle') || ~isa(res.handle, 'fricont_handle')
    error('fricont:argument', 'fricont_resume: res must come from fricont_trace');
  end
  if nargin < 2
    monitor = [];
  end
  if ~isempty(monitor) && ~isa(monitor, 'function_handle')
    error('fricont:argument', 'fricont_resume: monitor must be a function handle or []');
  end
  id = res.handle.id;
  fricont_drive(id, res.load, res.n, 'run', monitor);
  cur = fricont_mex('path_result', id);
  for f = fieldnames(cur).'
    res.(f{1}) = cur.(f{1});
  end
end
