# Regression guard of the wave flume: a short flume (2 wavelengths, damping zone over the last 0.75) at h/dp = 8,
# c0 = 7 sqrt(g h), the example's defaults otherwise (h_sph = 2 dp, second-order piston signal, no artificial
# viscosity: alpha = 0 since session 5), one gauge one wavelength from the paddle, analysed from one period after the
# linear arrival (--settle 1, so the run stays short: about 30 s of one loaded core).
#  - period within 1 %: the paddle imposes T; zero-crossing periods over 2-3 waves sampled at T/40 are within
#    0.7 % (measured -0.11 %), so a larger error means the paddle or the gauge is broken;
#  - height within 5 % of the target (the issue's criterion at one wavelength): measured -1.8 % here (h_sph = 2 dp;
#    -3.6 % with alpha = 0.01), against -14 % with the old h_sph = 1.3 dp (docs/flume.md, suspect 8), so a return to the
#    narrow kernel, a wrong Biesel stroke or a paddle that does not move fails.
if(TARGET wave_flume)
  add_test(NAME waves.flume_coarse
           COMMAND wave_flume --resolution 8 --sound-speed 7 --length 2 --damping-length 0.75 --gauges 1 --ramp 1
                   --order 2 --settle 1 --waves 2.5 --height-tolerance 0.05 --period-tolerance 0.01
                   --output ${CMAKE_CURRENT_BINARY_DIR}/regression/wave_flume)
  set_tests_properties(waves.flume_coarse PROPERTIES ENVIRONMENT "OMP_WAIT_POLICY=passive" TIMEOUT 120)
endif()

# The scheme's own wave dynamics without paddle or absorber: the flume's wave as a standing wave in a closed tank
# (examples/standing_wave, h/dp = 8, h_sph = 2 dp, 8 periods: about 15 s of one core). Measured: period -3.2 % of
# linear theory, amplitude loss 4.8 % per period (h/dp = 12: -2.6 %, 2.9 %); with h_sph = 1.3 dp -6.8 % and 17.8 %.
# The standing wave of this steepness (Ursell number 20) is not linear, so its own period shift and the exchange of
# energy with the tank's other modes are not zero; the bounds (5 % and 10 % per period) therefore guard against the
# narrow kernel's errors, which are twice and four times the measured ones, not against a few per cent.
if(TARGET standing_wave)
  add_test(NAME waves.standing_wave
           COMMAND standing_wave --resolution 8 --period-tolerance 0.05 --loss-tolerance 0.10
                   --output ${CMAKE_CURRENT_BINARY_DIR}/regression/standing_wave)
  set_tests_properties(waves.standing_wave PROPERTIES ENVIRONMENT "OMP_WAIT_POLICY=passive;OMP_NUM_THREADS=1"
                                                      TIMEOUT 120)
endif()
