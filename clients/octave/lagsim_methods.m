function list = lagsim_methods(class_name)
%LAGSIM_METHODS  The public methods of a Java class of lagsim's jars, with their signatures.
%   LAGSIM_METHODS('lagsim.examples.Messages') prints one method a line (return type, name,
%   argument types); LIST = LAGSIM_METHODS(NAME) returns them as a cell array of strings.
%   Call lagsim_setup() first.
%
%   In MATLAB this is methods(NAME, '-full'). GNU Octave 7's methods(NAME) looks NAME up on
%   the JVM's system class loader, which does not see the jars javaaddpath (and so
%   lagsim_setup) added: it fails with "java.lang.ClassNotFoundException" although
%   javaMethod finds the class. Here the class is looked up through the loader that
%   loaded lagsim's types instead. (With the jars on Octave's static class path, a
%   javaclasspath.txt in the folder Octave starts in, methods(NAME) works as well.)
if exist('OCTAVE_VERSION', 'builtin') == 0
    found = methods(class_name, '-full');
else
    loader = javaMethod('getClassLoader', javaMethod('getClass', javaObject('lagsim.control_t')));
    klass = javaMethod('forName', 'java.lang.Class', class_name, true, loader);
    found = strsplit(char(javaMethod('getMethods', 'org.octave.ClassHelper', klass)), ';');
end
found = found(:);
if nargout > 0
    list = found;
else
    fprintf('%s\n', found{:});
end
end
