function navego_check(in_file, out_file, navego_dir)
% navego_check: run NaveGo's ins_gnss on a drive exported by tools/navego_check.py.
%
%   navego_check(in_file, out_file, navego_dir)
%
% in_file:    a MAT file (-v7) holding the structs imu and gnss in NaveGo's layout (ins_gnss.m's header), the
%             GNSS fixes inside the outages already removed, and att_mode.
% out_file:   where nav_e.t, nav_e.lat, nav_e.lon, nav_e.h, nav_e.tg and nav_e.b are written (MAT -v7).
% navego_dir: NaveGo's source (../shared/navego-v1.4): read from there at run time, never copied here (the
%             diagnostic run reads a temporary copy with three lines changed: navego_check.py, BIAS_FEEDBACK_PATCH).
%
% This file is ours (MIT); NaveGo (LGPL-3.0) is only called.

  if exist('OCTAVE_VERSION', 'builtin')
    pkg load control            % ins_gnss calls obsv() (Debian: octave-control); loaded first, because it has a
  end                           % kalman() of its own that NaveGo's kalman.m must shadow (addpath puts it in front)
  for sub = {'conversions', 'ins', 'ins-gnss', 'simulation', 'misc', 'performance-analysis'}
    addpath(fullfile(navego_dir, sub{1}));
  end
  data = load(in_file);
  nav_e = ins_gnss(data.imu, data.gnss, data.att_mode);
  t = nav_e.t; lat = nav_e.lat; lon = nav_e.lon; h = nav_e.h;
  tg = nav_e.tg; b = nav_e.b;   % the bias estimates at the GNSS epochs, [gb_dyn ab_dyn] (rad/s, m/s^2)
  save('-v7', out_file, 't', 'lat', 'lon', 'h', 'tg', 'b');
end
