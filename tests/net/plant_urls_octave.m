function plant_urls_octave(table)
%PLANT_URLS_OCTAVE  Checks lagsim_plant_urls (clients/octave) against the cases of TABLE
%(tests/net/plant_urls.txt); an error unless every case passes (octave --eval exits 1).
lagsim_setup();
lines = strsplit(fileread(table), sprintf('\n'));
cases = 0;
fails = 0;
for k = 1:numel(lines)
    line = strtrim(lines{k});
    if isempty(line) || line(1) == '#'
        continue;
    end
    f = strtrim(strsplit(line, ' | '));
    base = f{1};
    if strcmp(base, '(none)')
        base = '';
    end
    try
        [s, c] = lagsim_plant_urls(base);
    catch
        s = 'ERROR';
        c = 'ERROR';
    end
    cases = cases + 1;
    if ~strcmp(s, f{2}) || ~strcmp(c, f{3})
        fprintf('FAIL: ''%s'' gives %s %s, expected %s %s\n', f{1}, s, c, f{2}, f{3});
        fails = fails + 1;
    end
end
fprintf('lagsim_plant_urls: %d cases, %d failures\n', cases, fails);
if fails > 0 || cases < 10
    error('plant_urls_octave: %d of %d cases failed', fails, cases);
end
end
