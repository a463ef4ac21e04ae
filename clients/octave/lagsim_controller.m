classdef lagsim_controller < handle
%LAGSIM_CONTROLLER  What a MATLAB or GNU Octave controller of lagsim needs: options,
%connect, wait for the scene, answer states until the run ends, a summary line. The
%twin of the Python, Lua, Java and C controllers' shared setup (same options, same ends,
%same summary).
%
%   ctl = lagsim_controller('dipc_balance', 'DIPC', 'dipc');
%   ctl.option('r', '1', 'input weight');          % the example's own options
%   if ~ctl.start(varargin{:}), return; end        % parses, connects, waits for the scene
%   st = ctl.next_state();                         % each newest state once
%   while ~isempty(st)
%       ctl.command(st.sim_time, {'theta0'}, u);   % answers that state
%       st = ctl.next_state();
%   end
%   ctl.finish(sprintf('states=%d', n));           % "dipc_balance: summary end=... states=..."
%
%   A scene with a reference: key has lagsimd publish a reference_t on <PREFIX>_REFERENCE
%   just before each state, with that state's sim_time; after next_state, ctl.reference
%   is the one that belongs to the state it returned (docs/clients.md, "Reading the
%   reference"):
%
%   k = ctl.joint(ctl.reference, 'q1');            % 0: no reference for q1 (or none at all)
%   if k > 0, r = ctl.reference.r(k); rdot = ctl.reference.rdot(k); end
%
%   Options: --prefix P, --url URL (the plant's lcm.url; commands go to the next port;
%   none: the URL a host's directory on LCM's default bus names for P, if one does),
%   --duration S (s of sim time from the first state; 0: until the daemon stops),
%   --timeout S (wall s without a scene, or without any message once running),
%   --trace FILE (each answered state and the efforts sent, %.17g), -q, --help.
%   A run ends (next_state returns []) when the daemon publishes its stop event, when
%   nothing came from it (state, status or event) for --timeout wall s, or after
%   --duration s of sim time; ctl.end_reason says which: stop, silence, duration.
%   No scene within --timeout, or another model's, is an error (lagsim:noscene,
%   lagsim:model); a bad option is lagsim:usage. Run from a shell, octave --eval exits 1
%   on any of these and 0 after a run that ended.
%
%   Messages come through LCM's Java library (lcm.jar) into a MessageAggregator that
%   queues them on LCM's receive thread; they are decoded here, one at a time, by lagsim's
%   bounded Java decoder (lagsim.examples.BoundedInput), which refuses forged string
%   lengths before they allocate and keeps only messages that encode back to the bytes
%   received with every number finite; the rest are counted in ctl.dropped.

    properties
        name            % the program's name, at the start of its lines
        model           % the model it controls ('dipc', 'cartpole', ...)
        quiet = false   % -q
        scene = []      % the scene description (a lagsim.scene_t)
        params = struct()   % the scene's parameters by name: params.m0, params.l1, ...
        end_reason = '' % stop, silence or duration, once the run has ended
        dropped = 0     % messages on the plant's channels that did not decode whole
        repeats = 0     % copies of the state answered last, answered again (see next_state)
        held = 0        % states held until the scene of their generation came
        % the scene's reference for the state next_state returned last, as a struct
        % (sim_time, step, name: a cell of joint names, r, rdot, rddot: columns): the one
        % published with it (the same sim_time), or, when UDP lost that one, the last one
        % received before it (an older sim_time, counted in references_stale); [] before
        % the first (a scene without a reference publishes none)
        reference = []
        references_stale = 0   % states handed out whose own reference did not come
    end

    properties (Access = private)
        keys = {}
        values = {}
        helps = {}
        lc = []         % the plant's state URL: states, status, events, scene
        lc_cmd = []     % its command URL: commands and control requests
        agg = []
        prefix = ''
        duration = 0
        timeout = 5
        trace = -1
        latest = []     % the newest state received and not yet handled
        ref_newest = [] % the newest reference received (a lagsim.reference_t)
        ref_latest = [] % the one that was newest when latest came (its own, unless lost)
        current = []    % the state handed out last
        last_cmd = []   % the command that answered it
        stopped = false
        heard = []      % tic of the last message from the daemon
        t_first = NaN
    end

    methods
        function obj = lagsim_controller(name, default_prefix, model)
            obj.name = name;
            obj.model = model;
            obj.option('prefix', default_prefix, 'channel prefix');
            obj.option('url', '', ['the plant''s LCM URL, its lcm.url (default: the URL a ' ...
                                   'host''s directory on LCM''s default bus names for --prefix, ' ...
                                   'else LCM''s default, honours LCM_DEFAULT_URL); commands go ' ...
                                   'to the next port']);
            obj.option('duration', '0', ['stop after S s of sim time from the first state ' ...
                                         '(0: until the daemon stops)']);
            obj.option('timeout', '5', ['wall s without a scene, or without any message ' ...
                                        'once running, before ending']);
            obj.option('trace', '', 'write each answered state and the efforts sent to this file');
        end

        function option(obj, key, default, help)
            % Declares --KEY with a default value (a string) and a help line.
            k = find(strcmp(obj.keys, key));
            if isempty(k)
                k = numel(obj.keys) + 1;
            end
            obj.keys{k} = key;
            obj.values{k} = default;
            obj.helps{k} = help;
        end

        function v = get(obj, key)
            % The value of --KEY, a string.
            v = obj.values{strcmp(obj.keys, key)};
        end

        function v = number(obj, key)
            % The value of --KEY as a finite number, or a lagsim:usage error.
            v = str2double(obj.get(key));
            if ~isfinite(v) || ~isreal(v)
                obj.usage_error(sprintf('--%s wants a number, not ''%s''', key, obj.get(key)));
            end
        end

        function v = list(obj, key, n)
            % The value of --KEY as N comma-separated finite numbers (a row), or lagsim:usage.
            parts = strsplit(obj.get(key), ',');
            v = str2double(parts);
            if numel(v) ~= n || any(~isfinite(v)) || ~isreal(v)
                obj.usage_error(sprintf('--%s wants %d comma-separated numbers', key, n));
            end
        end

        function usage_error(obj, msg)
            error('lagsim:usage', '%s: %s', obj.name, msg);
        end

        function ok = start(obj, varargin)
            % Parses the options, connects, subscribes, waits for the scene description.
            % False after --help (the usage was printed): the caller returns.
            ok = false;
            i = 1;
            while i <= numel(varargin)
                a = varargin{i};
                if ~ischar(a)
                    obj.usage_error('options are strings: ''--prefix'', ''DIPC'', ...');
                elseif strcmp(a, '--help') || strcmp(a, '-h')
                    obj.usage();
                    return;
                elseif strcmp(a, '-q')
                    obj.quiet = true;
                elseif numel(a) > 2 && strncmp(a, '--', 2) && any(strcmp(obj.keys, a(3:end))) ...
                        && i < numel(varargin) && ischar(varargin{i + 1})
                    obj.values{strcmp(obj.keys, a(3:end))} = varargin{i + 1};
                    i = i + 1;
                else
                    obj.usage();
                    obj.usage_error(sprintf('unknown or incomplete option ''%s''', a));
                end
                i = i + 1;
            end
            obj.prefix = obj.get('prefix');
            obj.duration = obj.number('duration');
            obj.timeout = obj.number('timeout');
            if ~(obj.timeout > 0) || ~(obj.duration >= 0)
                obj.usage_error('--timeout must be > 0 and --duration >= 0');
            end
            lagsim_setup();
            url = obj.get('url');
            if isempty(url)
                url = obj.located();
            end
            try
                [state_url, command_url] = lagsim_plant_urls(url);
            catch err
                obj.usage_error(['--url: ' err.message]);
            end
            if ~isempty(obj.get('trace'))
                obj.trace = fopen(obj.get('trace'), 'w');
                if obj.trace < 0
                    obj.usage_error(['--trace: cannot write ' obj.get('trace')]);
                end
            end
            obj.lc = lagsim_lcm(state_url);
            if strcmp(command_url, state_url)
                obj.lc_cmd = obj.lc;
            else
                obj.lc_cmd = lagsim_lcm(command_url);
            end
            % LCM's receive thread queues what comes (at most 10000 messages, 16 MB; beyond
            % that the oldest go); this thread takes them out one at a time
            obj.agg = javaObject('lcm.lcm.MessageAggregator');
            obj.agg.setMaxMessages(10000);
            obj.agg.setMaxBufferSize(16 * 1024 * 1024);
            ch = [obj.prefix '_'];
            obj.lc.subscribe([javaMethod('quote', 'java.util.regex.Pattern', ch) ...
                              '(STATE|SCENE|EVENT|STATUS|REFERENCE)'], obj.agg);
            obj.heard = tic;
            % subscribed: from here on no state is missed (test harnesses wait for this line)
            obj.say('%s: waiting for the scene description on %sSCENE\n', obj.name, ch);
            started = tic;
            asked = -Inf;
            while isempty(obj.scene)
                if toc(started) >= obj.timeout
                    error('lagsim:noscene', ['%s: no scene on %sSCENE within %g s (is lagsimd ' ...
                          'running with this prefix?)'], obj.name, ch, obj.timeout);
                end
                if toc(started) - asked >= 0.25   % DESCRIBE every 0.25 s until the scene comes
                    obj.ask_scene();
                    asked = toc(started);
                end
                obj.pump(50);
            end
            if ~strcmp(char(obj.scene.model), obj.model)
                error('lagsim:model', '%s: prefix %s runs model %s, not %s', obj.name, ...
                      obj.prefix, char(obj.scene.model), obj.model);
            end
            ok = true;
        end

        function url = located(obj)
            % No --url: the URL a host's directory on LCM's default bus names for the
            % prefix (lagsim.examples.Locate, the C library's rule, 1 s at most), else ''
            % (LCM's default: a plant there, or one not started yet).
            url = '';
            try
                l = javaMethod('plant', 'lagsim.examples.Locate', obj.prefix, 1.0);
            catch err
                obj.usage_error(['--prefix: ' err.message]);
            end
            if l.host()
                url = char(l.url());
                obj.say('%s: prefix %s runs on %s (the host''s directory)\n', obj.name, ...
                        obj.prefix, url);
            end
        end

        function ask_scene(obj)
            % DESCRIBE: the daemon answers with its scene.
            describe = javaObject('lagsim.control_t');
            obj.lc_cmd.publish([obj.prefix '_CONTROL'], ...
                javaMethod('control', 'lagsim.examples.Messages', describe.DESCRIBE));
        end

        function s = with_scene(obj, s)
            % S, or the newest state since, once the scene of its generation came (the
            % daemon publishes it just before the first state of a generation; DESCRIBE
            % asks for it again every 0.25 s, for when UDP lost it); [] when the run ended
            % first. So the law never answers a state with another run's or scene's
            % parameters (docs/clients.md, the scene rule).
            asked = -Inf;
            started = tic;
            while double(s.generation) ~= double(obj.scene.generation)
                if obj.stopped
                    obj.end_reason = 'stop';
                    s = [];
                    return;
                end
                if toc(obj.heard) > obj.timeout
                    obj.end_reason = 'silence';
                    s = [];
                    return;
                end
                if toc(started) - asked >= 0.25
                    obj.ask_scene();
                    asked = toc(started);
                end
                obj.pump(20);
                if ~isempty(obj.latest)   % a newer state: that one is answered
                    s = obj.latest;
                    obj.latest = [];
                end
            end
        end

        function st = next_state(obj)
            % The newest state not yet handled, as a struct (sim_time, step, generation,
            % name: a cell of joint names, position, velocity, effort: columns), or [] once
            % the run has ended (obj.end_reason says why). It comes only once obj.scene
            % (and obj.params) is the scene of its generation.
            %
            % Each sim_time is answered once by the control law, and only the newest state
            % is: what queued behind a newer state is dropped unanswered. A controller that
            % answers every message in the order it came, re-sent copies included, falls
            % behind in lockstep: the daemon publishes a state again every
            % realtime.lockstep_retry (20 ms) until an answer reaches it, so each answer
            % that takes longer than that queues a copy, and answering the copies costs the
            % time in which the next ones are sent. A copy of the state answered last that
            % is still the newest message means that answer was lost on the way: the same
            % command goes again, without running the law (counted in obj.repeats).
            st = [];
            if ~isempty(obj.end_reason)
                return;
            end
            while true
                while isempty(obj.latest)
                    if obj.stopped
                        obj.end_reason = 'stop';
                        return;
                    end
                    if toc(obj.heard) > obj.timeout
                        obj.end_reason = 'silence';
                        return;
                    end
                    obj.pump(50);
                end
                obj.pump(0);   % what came meanwhile: the newest state is answered
                s = obj.latest;
                r = obj.ref_latest;
                obj.latest = [];
                % a state is known by its generation and sim time: every run starts again
                % at sim time 0
                if isempty(obj.current) || double(s.generation) ~= obj.current.generation ...
                        || double(s.step) ~= obj.current.step ...
                        || s.sim_time ~= obj.current.sim_time || isempty(obj.last_cmd)
                    if double(s.generation) ~= double(obj.scene.generation)
                        obj.held = obj.held + 1;
                        s = obj.with_scene(s);
                        if isempty(s)
                            return;
                        end
                        r = obj.ref_latest;
                    end
                    break;
                end
                obj.lc_cmd.publish([obj.prefix '_COMMAND'], obj.last_cmd);
                obj.repeats = obj.repeats + 1;
            end
            % the Java arrays, copied to Octave/MATLAB values once
            names = s.name;
            position = s.position;
            velocity = s.velocity;
            effort = s.effort;
            st = struct('sim_time', s.sim_time, 'step', double(s.step), ...
                        'generation', double(s.generation), ...
                        'name', {cell(1, numel(names))}, 'position', double(position(:)), ...
                        'velocity', double(velocity(:)), 'effort', double(effort(:)));
            for k = 1:numel(names)
                st.name{k} = char(names(k));
            end
            obj.current = st;
            obj.last_cmd = [];
            obj.reference = [];
            if ~isempty(r)
                names = r.name;
                rv = r.r;
                rdot = r.rdot;
                rddot = r.rddot;
                ref = struct('sim_time', r.sim_time, 'step', double(r.step), ...
                             'name', {cell(1, numel(names))}, 'r', double(rv(:)), ...
                             'rdot', double(rdot(:)), 'rddot', double(rddot(:)));
                for k = 1:numel(names)
                    ref.name{k} = char(names(k));
                end
                obj.reference = ref;
                if ref.sim_time ~= st.sim_time
                    obj.references_stale = obj.references_stale + 1;
                end
            end
            if isnan(obj.t_first)
                obj.t_first = st.sim_time;
            end
            if obj.duration > 0 && ...
                    st.sim_time - obj.t_first >= obj.duration - 0.5 * obj.scene.control_period
                obj.end_reason = 'duration';   % this state is still answered; the next call ends
            end
        end

        function command(obj, sim_time, names, efforts)
            % Publishes EFFORTS (N or N m; a NaN or an infinity goes as 0) for the joints
            % NAMES (a cell of strings), answering the state at SIM_TIME.
            efforts = double(efforts(:));
            efforts(~isfinite(efforts)) = 0;
            if ischar(names)
                names = {names};
            end
            st = obj.current;
            gen = 0;   % the generation of the state it answers (0: none yet)
            if ~isempty(st)
                gen = st.generation;
            end
            if numel(names) == 1   % a one-element vector reaches Java as a scalar
                cmd = javaMethod('command', 'lagsim.examples.Messages', gen, sim_time, ...
                                 names{1}, efforts);
            else
                cmd = javaMethod('command', 'lagsim.examples.Messages', gen, sim_time, ...
                                 names, efforts);
            end
            obj.lc_cmd.publish([obj.prefix '_COMMAND'], cmd);
            if ~isempty(st) && st.sim_time == sim_time
                obj.last_cmd = cmd;
                if obj.trace >= 0
                    % sim_time, positions, velocities, efforts sent: %.17g reads back exactly
                    fprintf(obj.trace, '%s\n', strtrim(sprintf('%.17g ', ...
                            [st.sim_time; st.position; st.velocity; efforts])));
                end
            end
        end

        function k = joint(obj, st, joint_name) %#ok<INUSL>
            % The index of JOINT_NAME in a state's or a reference's joints (ST: a struct
            % from next_state, or ctl.reference), or 0 (none; ST [] gives 0 too).
            k = [];
            if ~isempty(st)
                k = find(strcmp(st.name, joint_name), 1);
            end
            if isempty(k)
                k = 0;
            end
        end

        function finish(obj, summary)
            % Prints the summary line: "<name>: summary end=<why> <summary> dropped=N
            % repeats=N", then, when a reference came (a scene with a reference),
            % " references_stale=N".
            if obj.trace >= 0
                fclose(obj.trace);
                obj.trace = -1;
            end
            stale = '';
            if ~isempty(obj.ref_newest)
                stale = sprintf(' references_stale=%d', obj.references_stale);
            end
            obj.say('%s: summary end=%s %s dropped=%d repeats=%d%s\n', obj.name, obj.end_reason, ...
                    summary, obj.dropped, obj.repeats, stale);
        end

        function say(obj, varargin) %#ok<INUSL>
            % fprintf to the standard output, flushed (a pipe reads it at once in Octave).
            fprintf(varargin{:});
            if exist('OCTAVE_VERSION', 'builtin')
                fflush(stdout);
            end
        end
    end

    methods (Access = private)
        function usage(obj)
            fprintf('usage: %s [options]\n', obj.name);
            for k = 1:numel(obj.keys)
                d = obj.values{k};
                if isempty(d)
                    d = 'none';
                end
                fprintf('  --%-10s %s (default %s)\n', obj.keys{k}, obj.helps{k}, d);
            end
            fprintf('  -q           quiet: summary only\n');
        end

        function pump(obj, wait_ms)
            % Handles every queued message, waiting up to WAIT_MS ms for the first.
            m = obj.agg.getNextMessage(wait_ms);
            while ~isempty(m)
                obj.handle(m);
                if obj.agg.numMessagesAvailable() > 0
                    m = obj.agg.getNextMessage(0);
                else
                    m = [];
                end
            end
        end

        function handle(obj, m)
            obj.heard = tic;
            channel = char(m.channel);
            kind = channel(numel(obj.prefix) + 2:end);
            if strcmp(kind, 'STATUS')
                return;
            end
            switch kind
                case 'STATE'
                    msg = lagsim_decode(m.data, 'joint_state_t');
                case 'REFERENCE'
                    msg = lagsim_decode(m.data, 'reference_t');
                case 'SCENE'
                    msg = lagsim_decode(m.data, 'scene_t');
                otherwise
                    msg = lagsim_decode(m.data, 'event_t');
            end
            if isempty(msg)
                obj.dropped = obj.dropped + 1;
            elseif strcmp(kind, 'STATE')
                obj.latest = msg;
                obj.ref_latest = obj.ref_newest;
            elseif strcmp(kind, 'REFERENCE')
                obj.ref_newest = msg;
            elseif strcmp(kind, 'SCENE')
                obj.scene = msg;
                obj.params = struct();
                names = msg.param_name;   % a Java array: copied before indexing
                values = msg.param_value;
                for k = 1:numel(values)
                    if isvarname(char(names(k)))
                        obj.params.(char(names(k))) = values(k);
                    end
                end
            elseif strcmp(kind, 'EVENT') && strcmp(char(msg.kind), 'stop')
                obj.stopped = true;
            end
        end
    end
end
