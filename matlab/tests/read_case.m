function c = read_case(dir)
%READ_CASE Reads a problem in the exchange format (SPEC section 7) for the tests:
%   c.A, c.N, c.T (sparse), c.f0, c.f1, c.gap, c.F, c.alpha_start, c.alpha_end.
  c.A = read_mtx(fullfile(dir, 'A.mtx'));
  c.N = read_mtx(fullfile(dir, 'N.mtx'));
  c.T = read_mtx(fullfile(dir, 'T.mtx'));
  c.f0 = load_vec(fullfile(dir, 'f0.txt'));
  c.f1 = load_vec(fullfile(dir, 'f1.txt'));
  p = size(c.N, 1);
  if exist(fullfile(dir, 'gap.txt'), 'file')
    c.gap = load_vec(fullfile(dir, 'gap.txt'));
  else
    c.gap = zeros(p, 1);
  end
  meta = fileread(fullfile(dir, 'meta.json'));
  c.alpha_start = json_number(meta, 'alpha_start');
  c.alpha_end = json_number(meta, 'alpha_end');
  tok = regexp(meta, '"F"\s*:\s*(\[[^\]]*\]|[-+0-9.eE]+)', 'tokens', 'once');
  c.F = str2num(tok{1}); %#ok<ST2NM>
  c.F = c.F(:);
end

function x = json_number(text, key)
  tok = regexp(text, ['"' key '"\s*:\s*([-+0-9.eE]+)'], 'tokens', 'once');
  x = str2double(tok{1});
end

function x = load_vec(file)
  fid = fopen(file, 'r');
  x = fscanf(fid, '%f');
  fclose(fid);
end

function M = read_mtx(file)
  fid = fopen(file, 'r');
  header = fgetl(fid);
  line = fgetl(fid);
  while ischar(line) && ~isempty(line) && line(1) == '%'
    line = fgetl(fid);
  end
  dims = sscanf(line, '%d');
  t = fscanf(fid, '%f', [3, dims(3)]);
  fclose(fid);
  M = sparse(t(1, :), t(2, :), t(3, :), dims(1), dims(2));
  if ~isempty(strfind(header, 'symmetric'))
    M = M + tril(M, -1).';
  end
end
