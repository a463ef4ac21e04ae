function jars = lagsim_setup(jar_dir)
%LAGSIM_SETUP  Puts LCM's Java classes and lagsim's on the Java class path.
%   LAGSIM_SETUP() finds lcm.jar (Debian's liblcm-java), lagsim_types.jar (the lcm-gen
%   types) and lagsim_examples.jar (BoundedInput, PlantUrls) and adds those not on the
%   class path yet with javaaddpath. It looks in JAR_DIR when given, then beside a build
%   tree's copy of this file (<build>/octave/..), beside an installed one
%   (<prefix>/share/lagsim/octave -> <prefix>/share/java), in /usr/share/java and in
%   /usr/local/share/java. JARS, when asked for, lists the three files.
%
%   Call it before creating any variable: in MATLAB, javaaddpath clears the workspace's
%   variables and global variables. It runs unchanged in GNU Octave and MATLAB.
if nargin < 1
    jar_dir = '';
end
here = fileparts(mfilename('fullpath'));
dirs = {jar_dir, fullfile(here, '..'), fullfile(here, '..', '..', 'java'), ...
        '/usr/share/java', '/usr/local/share/java'};
dirs = dirs(~cellfun(@isempty, dirs));
names = {'lcm.jar', 'lagsim_types.jar', 'lagsim_examples.jar'};
% a jar of that name already on the class path is kept (a second copy of a class would
% be a second class, and MATLAB warns about an entry on both paths)
present = javaclasspath('-all');
if ischar(present)
    present = cellstr(present);
end
jars = cell(1, numel(names));
add = {};
for k = 1:numel(names)
    for p = 1:numel(present)
        [~, base, ext] = fileparts(present{p});
        if strcmp([base ext], names{k})
            jars{k} = present{p};
        end
    end
    for d = 1:numel(dirs)
        f = fullfile(dirs{d}, names{k});
        if isempty(jars{k}) && exist(f, 'file') == 2
            jars{k} = f;
            add{end + 1} = f; %#ok<AGROW>
        end
    end
    if isempty(jars{k})
        error('lagsim:setup', ['lagsim_setup: no %s (looked in %s); install liblcm-java, ' ...
              'build lagsim with javac, or pass the folder that holds it'], names{k}, ...
              strjoin(dirs, ', '));
    end
end
if ~isempty(add)
    javaaddpath(add);
end
end
