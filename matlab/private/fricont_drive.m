function [status, count] = fricont_drive(id, load, n, job, varargin)
%FRICONT_DRIVE Runs a library call on path id, evaluating the load function whenever
%   the library asks for f(alpha) or f'(alpha), and the monitor after each transition
%   point of a 'run' (see fricont_mex.c); for a basis load, load.w(alpha) gives the
%   k-by-2 weights [phi dphi] (load.k = k). For job 'run', varargin is {monitor}: a
%   function handle or [] (none). The functions are evaluated here, in MATLAB, between
%   MEX calls. An error in the load function is kept, the library is told to stop (the
%   path ends, 'failed'), and the error is raised afterwards as fricont:load; an error in
%   the monitor stops the path ('stopped') and is rethrown as it is. On the way out,
%   also after an error or Ctrl-C here, a request left unanswered is refused ('settle').
  monitor = [];
  args = varargin;
  if strcmp(job, 'run')
    if ~isempty(args)
      monitor = args{1};
    end
    args = {double(~isempty(monitor))};
    nout = 1;
    if ~isempty(monitor)
      try
        nout = nargout(monitor);   % 0: a function without output never stops the path
      catch
        nout = 1;
      end
    end
  end
  [what, value, count] = fricont_mex('path_call', id, job, args{:});
  settle = onCleanup(@() fricont_mex('settle', id));
  failure = [];
  monitor_failure = [];
  failed_at = NaN;
  while ~strcmp(what, 'done')
    v = [];
    if isempty(failure) && isempty(monitor_failure) && strcmp(what, 'monitor')
      try
        if nout == 0
          monitor(value(1), value(2), value(3), value(4));
          v = false;
        else
          v = monitor(value(1), value(2), value(3), value(4));
        end
        if ~isscalar(v) || ~(islogical(v) || (isnumeric(v) && isreal(v) && (v == 0 || v == 1)))
          error('fricont:monitor', ['fricont: the monitor must return true (stop) or ' ...
                'false (go on), got %s'], describe(v));
        end
        v = logical(v);
      catch err
        monitor_failure = err;
        v = [];
      end
    elseif isempty(failure) && isempty(monitor_failure)
      try
        if strcmp(what, 'w')
          v = load.w(value);
          if ~isnumeric(v) || ~isreal(v) || ~isequal(size(v), [load.k 2])
            error('fricont:load', ['the weights function must return a real k-by-2 matrix ' ...
                  '[phi dphi] (k = %d), got %s'], load.k, mat2str(size(v)));
          end
        elseif strcmp(what, 'f')
          v = load.f(value);
        else
          v = load.df(value);
        end
        if ~strcmp(what, 'w') && (~isnumeric(v) || ~isreal(v) || numel(v) ~= n)
          error('fricont:load', ['the load function must return a real vector of ' ...
                'n = %d values (got %d)'], n, numel(v));
        end
        v = full(double(v(:)));             % (weights: [phi; dphi])
      catch err
        failure = err;
        failed_at = value;
        v = [];
      end
    end
    [what, value, count] = fricont_mex('resume', id, v);
  end
  status = value;
  if ~isempty(monitor_failure)
    rethrow(monitor_failure);
  end
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

% A short description of what a monitor returned.
function s = describe(v)
  if isnumeric(v) && isscalar(v)
    s = sprintf('%s %g', class(v), v);
  else
    s = sprintf('a %s of size %s', class(v), mat2str(size(v)));
  end
end
