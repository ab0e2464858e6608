function c = fricont_read_case(dir)
%FRICONT_READ_CASE Reads a problem directory in fricont's exchange format.
%
%   c = fricont_read_case(dir)
%
%   dir holds what `fricont gen-rect` and `fricont case-study` write and `fricont trace`
%   reads: A.mtx, N.mtx, T.mtx (Matrix Market), f0.txt, f1.txt (one number a line),
%   gap.txt (optional) and meta.json; each file may be gzip-compressed as NAME.gz.
%
%   c.A            n-by-n sparse stiffness, full storage (a 'symmetric' file, which
%                  stores one triangle, is expanded)
%   c.N, c.T       p-by-n sparse contact matrices
%   c.f0, c.f1     n-by-1: the load f(alpha) = f0 + alpha*f1
%   c.gap          p-by-1 (zeros without gap.txt)
%   c.F            friction: a scalar or a p-by-1 vector
%   c.alpha_start, c.alpha_end   the window
%   c.meta         meta.json as a struct (descriptive keys included)
%
%   So that, for example,
%     c = fricont_read_case(dir);
%     res = fricont_trace(c.A, c.N, c.T, c.f0, c.f1, c.F, [c.alpha_start c.alpha_end], ...
%                         struct('gap', c.gap));
%
%   Matrix Market files: 'matrix coordinate' or 'matrix array', field 'real' or
%   'integer', symmetry 'general' or 'symmetric'; 'pattern', 'complex', 'hermitian' and
%   'skew-symmetric' are errors. Repeated coordinate entries are summed (as sparse()
%   does). Errors (identifier fricont:read) name the file.
%
%   See also FRICONT_TRACE.
  c.meta = jsondecode(read_text(dir, 'meta.json'));
  for key = {'n', 'p', 'F', 'alpha_start', 'alpha_end'}
    if ~isfield(c.meta, key{1})
      error('fricont:read', 'fricont_read_case: %s has no "%s"', fullfile(dir, 'meta.json'), key{1});
    end
  end
  n = c.meta.n;
  p = c.meta.p;
  c.A = read_mtx(dir, 'A.mtx', n, n);
  c.N = read_mtx(dir, 'N.mtx', p, n);
  c.T = read_mtx(dir, 'T.mtx', p, n);
  c.f0 = read_vec(dir, 'f0.txt', n);
  c.f1 = read_vec(dir, 'f1.txt', n);
  if exist(fullfile(dir, 'gap.txt'), 'file') || exist(fullfile(dir, 'gap.txt.gz'), 'file')
    c.gap = read_vec(dir, 'gap.txt', p);
  else
    c.gap = zeros(p, 1);
  end
  c.F = double(c.meta.F(:));
  c.alpha_start = double(c.meta.alpha_start);
  c.alpha_end = double(c.meta.alpha_end);
end

% The text of dir/name, or of dir/name.gz when only that exists.
function [text, file] = read_text(dir, name)
  file = fullfile(dir, name);
  if ~exist(file, 'file') && exist([file '.gz'], 'file')
    tmp = tempname();
    unpacked = gunzip([file '.gz'], tmp);
    text = fileread(unpacked{1});
    delete(unpacked{1});
    rmdir(tmp);
    file = [file '.gz'];
  elseif exist(file, 'file')
    text = fileread(file);
  else
    error('fricont:read', 'fricont_read_case: %s not found', file);
  end
end

function x = read_vec(dir, name, len)
  [text, file] = read_text(dir, name);
  x = sscanf(text, '%f');
  if numel(x) ~= len || any(~isfinite(x))
    error('fricont:read', 'fricont_read_case: %s: expected %d finite numbers, read %d', ...
          file, len, numel(x));
  end
end

function M = read_mtx(dir, name, rows, cols)
  [text, file] = read_text(dir, name);
  lines = regexp(text, '\r?\n', 'split');
  head = lower(strsplit(strtrim(lines{1})));
  if numel(head) ~= 5 || ~strcmp(head{1}, '%%matrixmarket') || ~strcmp(head{2}, 'matrix')
    error('fricont:read', 'fricont_read_case: %s: not a Matrix Market matrix header: %s', ...
          file, lines{1}(1:min(end, 60)));
  end
  [format, field, symmetry] = deal(head{3}, head{4}, head{5});
  if ~any(strcmp(format, {'coordinate', 'array'})) || ~any(strcmp(field, {'real', 'integer'})) || ...
     ~any(strcmp(symmetry, {'general', 'symmetric'}))
    error('fricont:read', ['fricont_read_case: %s: %s %s %s is not supported ' ...
          '(coordinate or array; real or integer; general or symmetric)'], file, format, field, symmetry);
  end
  body = lines(2:end);
  body = body(~cellfun(@(l) isempty(strtrim(l)) || l(1) == '%', body));   % comments, blanks
  nums = sscanf(sprintf('%s\n', body{:}), '%f');
  if strcmp(format, 'coordinate')
    if numel(nums) < 3 || numel(nums) ~= 3 + 3 * nums(3)
      error('fricont:read', 'fricont_read_case: %s: the size line promises %d entries of 3 numbers', ...
            file, nums(min(3, end)));
    end
    t = reshape(nums(4:end), 3, []);
    M = sparse(t(1, :), t(2, :), t(3, :), nums(1), nums(2));
    lower_only = all(t(1, :) >= t(2, :));
    upper_only = all(t(1, :) <= t(2, :));
  else
    m = nums(1);
    if strcmp(symmetry, 'symmetric')
      expected = m * (m + 1) / 2;                  % the lower triangle, column by column
    else
      expected = m * nums(2);
    end
    if numel(nums) ~= 2 + expected
      error('fricont:read', 'fricont_read_case: %s: expected %d values, read %d', ...
            file, expected, numel(nums) - 2);
    end
    if strcmp(symmetry, 'symmetric')
      D = zeros(m);
      D(tril(true(m))) = nums(3:end);
    else
      D = reshape(nums(3:end), m, nums(2));
    end
    M = sparse(D);
    lower_only = true;
    upper_only = false;
  end
  if any(~isfinite(nonzeros(M)))
    error('fricont:read', 'fricont_read_case: %s: values must be finite', file);
  end
  if strcmp(symmetry, 'symmetric')
    if size(M, 1) ~= size(M, 2) || ~(lower_only || upper_only)
      error('fricont:read', 'fricont_read_case: %s: a symmetric file stores one triangle of a square matrix', file);
    end
    M = M + M.' - diag(diag(M));
  end
  if size(M, 1) ~= rows || size(M, 2) ~= cols
    error('fricont:read', 'fricont_read_case: %s is %d x %d, expected %d x %d (n, p from meta.json)', ...
          file, size(M, 1), size(M, 2), rows, cols);
  end
end
