function [status, count] = fricont_drive(id, load, n, job, varargin)
%FRICONT_DRIVE Runs a library call on path id, evaluating the load function whenever
%   the library asks for f(alpha) or f'(alpha) (see fricont_mex.c). The function is
%   evaluated here, in MATLAB, between MEX calls; an error it raises is kept, the
%   library is told to stop (the path ends), and the error is raised afterwards.
  [what, value, count] = fricont_mex('path_call', id, job, varargin{:});
  failure = [];
  failed_at = NaN;
  while ~strcmp(what, 'done')
    v = [];
    if isempty(failure)
      try
        if strcmp(what, 'f')
          v = load.f(value);
        else
          v = load.df(value);
        end
        if ~isnumeric(v) || ~isreal(v) || numel(v) ~= n
          error('fricont:load', ['the load function must return a real vector of ' ...
                'n = %d values (got %d)'], n, numel(v));
        end
        v = full(double(v(:)));
      catch err
        failure = err;
        failed_at = value;
        v = [];
      end
    end
    [what, value, count] = fricont_mex('resume', id, v);
  end
  status = value;
  if ~isempty(failure)
    error('fricont:load', 'fricont: the load function failed at alpha = %.17g: %s', ...
          failed_at, failure.message);
  end
  if status < 0
    msg = fricont_mex('path_error_message', id);
    name = fricont_mex('status_str', status);
    ident = strtok(name, ':');
    error(['fricont:' strrep(ident, 'FRICONT_', '')], 'fricont: %s', msg);
  end
end
