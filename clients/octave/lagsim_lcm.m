function lc = lagsim_lcm(url)
%LAGSIM_LCM  An LCM instance (lcm.lcm.LCM, from lcm.jar) on the LCM URL URL.
%
%   lc = lagsim_lcm('udpm://239.255.76.67:7667?ttl=0');
%   agg = javaObject('lcm.lcm.MessageAggregator');
%   lc.subscribe('DIPC_STATE', agg);                % a Java regular expression
%   m = agg.getNextMessage(100);                    % waits up to 100 ms; [] if none came
%
%   LCM's constructor takes its URLs as Java varargs, i.e. a String array: built here.
u = javaArray('java.lang.String', 1);
u(1) = javaObject('java.lang.String', url);
lc = javaObject('lcm.lcm.LCM', u);
end
