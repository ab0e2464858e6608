function fricont_build(prefix, outdir)
%FRICONT_BUILD Builds the MEX gateway fricont_mex from fricont_mex.c.
%
%   fricont_build(prefix)          % fricont installed under prefix (scripts/install.sh)
%   fricont_build(prefix, outdir)  % put fricont_mex.mex* into outdir (default: here)
%
%   prefix holds include/fricont.h and lib/libfricont.so; the MEX file records
%   prefix/lib as its run-time library path. Octave builds with mkoctfile --mex, MATLAB
%   with mex (the default, separate-complex API). The same as, from a shell:
%     mkoctfile --mex -I$PREFIX/include -L$PREFIX/lib -lfricont \
%               -Wl,-rpath,$PREFIX/lib fricont_mex.c                 (Octave)
%     mex -I$PREFIX/include -L$PREFIX/lib -lfricont ...
%         LDFLAGS='$LDFLAGS -Wl,-rpath,$PREFIX/lib' fricont_mex.c    (MATLAB)
  here = fileparts(mfilename('fullpath'));
  if nargin < 2 || isempty(outdir)
    outdir = here;
  end
  src = fullfile(here, 'fricont_mex.c');
  inc = fullfile(prefix, 'include');
  lib = fullfile(prefix, 'lib');
  if ~exist(fullfile(inc, 'fricont.h'), 'file')
    error('fricont:build', 'fricont_build: %s not found', fullfile(inc, 'fricont.h'));
  end
  out = fullfile(outdir, 'fricont_mex');
  if exist('OCTAVE_VERSION', 'builtin')
    [status, output] = system(sprintf(['mkoctfile --mex -I"%s" -L"%s" -lfricont ' ...
        '-Wl,-rpath,"%s" -o "%s" "%s"'], inc, lib, lib, out, src));
    if status ~= 0
      error('fricont:build', 'fricont_build: mkoctfile failed:\n%s', output);
    end
  else
    mex(['-I' inc], ['-L' lib], '-lfricont', ...
        ['LDFLAGS=$LDFLAGS -Wl,-rpath,' lib], '-output', out, src);
  end
end
