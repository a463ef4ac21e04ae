function [state_url, command_url] = lagsim_plant_urls(url)
%LAGSIM_PLANT_URLS  The two LCM URLs of a lagsim plant whose lcm.url is URL ('' or none:
%the environment's LCM_DEFAULT_URL, else LCM's default): the daemon publishes
%PREFIX_STATE, _STATUS, _EVENT and _SCENE on STATE_URL (the URL itself) and listens for
%PREFIX_COMMAND and _CONTROL on COMMAND_URL, the same group on the next port.
%
%   [state_url, command_url] = lagsim_plant_urls('');   % LCM's default URL
%
%   The rule is lagsim.examples.PlantUrls's (the Java one, checked against the C library's
%   cases); a URL a plant cannot have is an error. Needs lagsim_setup.
if nargin < 1
    url = '';
end
urls = javaMethod('both', 'lagsim.examples.PlantUrls', url);
state_url = char(urls(1));
command_url = char(urls(2));
end
