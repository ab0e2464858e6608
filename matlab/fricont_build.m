function fricont_build(where, outdir)
%FRICONT_BUILD Builds the MEX gateway fricont_mex from fricont_mex.c.
%
%   fricont_build()                 % the fricont this file belongs to (see below)
%   fricont_build(where)            % an install prefix or a repository (build tree)
%   fricont_build(where, outdir)    % put fricont_mex.mex* into outdir (default: the
%                                   % folder of this file)
%
%   Without an argument the library is found from where this file sits:
%     REPO/matlab/fricont_build.m              -> REPO/include, REPO/target/release
%                                                 (after `cargo build --release` in REPO;
%                                                 CARGO_TARGET_DIR is honoured)
%     PREFIX/share/fricont/matlab/fricont_build.m -> PREFIX/include, PREFIX/lib
%                                                 (after scripts/install.sh PREFIX)
%   where may name either kind of directory: a repository (it has Cargo.toml) uses
%   where/target/release, an install prefix where/lib.
%
%   The MEX file records the library's directory as its run-time search path (rpath),
%   so it runs without LD_LIBRARY_PATH. Octave builds with mkoctfile --mex, MATLAB with
%   mex (the default, separate-complex API). The same as, from a shell:
%     mkoctfile --mex -I$INC -L$LIB -lfricont -Wl,-rpath,$LIB fricont_mex.c        (Octave)
%     mex -I$INC -L$LIB -lfricont LDFLAGS='$LDFLAGS -Wl,-rpath,$LIB' fricont_mex.c (MATLAB)
  here = fileparts(mfilename('fullpath'));
  if nargin < 2 || isempty(outdir)
    outdir = here;
  end
  if nargin < 1 || isempty(where)
    if exist(fullfile(here, '..', 'Cargo.toml'), 'file')
      where = fullfile(here, '..');                  % REPO/matlab
    else
      where = fullfile(here, '..', '..', '..');      % PREFIX/share/fricont/matlab
    end
  end
  if ~ischar(where) || ~exist(where, 'dir')
    error('fricont:build', 'fricont_build: %s is not a directory', char(where));
  end
  old = cd(where);                                   % an absolute path without '..'
  where = pwd;
  cd(old);
  inc = fullfile(where, 'include');
  if exist(fullfile(where, 'Cargo.toml'), 'file')
    target = getenv('CARGO_TARGET_DIR');
    if isempty(target)
      target = fullfile(where, 'target');
    end
    lib = fullfile(target, 'release');
    hint = sprintf('build it first: cargo build --release (in %s)', where);
  else
    lib = fullfile(where, 'lib');
    hint = 'install it first: scripts/install.sh PREFIX';
  end
  if ~exist(fullfile(inc, 'fricont.h'), 'file')
    error('fricont:build', 'fricont_build: %s not found (%s)', fullfile(inc, 'fricont.h'), hint);
  end
  if ~exist(fullfile(lib, 'libfricont.so'), 'file')
    error('fricont:build', 'fricont_build: %s not found (%s)', fullfile(lib, 'libfricont.so'), hint);
  end
  src = fullfile(here, 'fricont_mex.c');
  out = fullfile(outdir, 'fricont_mex');
  if exist('OCTAVE_VERSION', 'builtin')
    [output, status] = mkoctfile('--mex', ['-I' inc], ['-L' lib], '-lfricont', ...
                                 ['-Wl,-rpath,' lib], '-o', out, src);
    if status ~= 0
      error('fricont:build', 'fricont_build: mkoctfile failed:\n%s', output);
    end
  else
    mex(['-I' inc], ['-L' lib], '-lfricont', ...
        ['LDFLAGS=$LDFLAGS -Wl,-rpath,' lib], '-output', out, src);
  end
end
