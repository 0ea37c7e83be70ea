# cmake -DPREFIX=<install> -DCC=<C compiler> -DSOURCE=<cadence_c.c> -DOUT=<exe> -DTABLE=<csv>
#       -P pkg_config_build.cmake
# Builds the C consumer with nothing but the compiler and `pkg-config rdyn-reduced` (the way
# a Makefile or a Simulink S-function build would), then runs it.
set(ENV{PKG_CONFIG_PATH} "${PREFIX}/lib/pkgconfig")
execute_process(COMMAND pkg-config --cflags --libs rdyn-reduced OUTPUT_VARIABLE flags
  RESULT_VARIABLE rc OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pkg-config does not know rdyn-reduced under ${PREFIX}/lib/pkgconfig")
endif()
separate_arguments(flags UNIX_COMMAND "${flags}")
execute_process(COMMAND "${CC}" -std=c99 -O2
  "-DRDYN_CONSUMER_SCENE=\"${PREFIX}/share/rdyn/scenes/bicycle.yaml\"" "${SOURCE}" -o "${OUT}" ${flags}
  RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${CC} with the pkg-config flags failed: ${err}")
endif()
execute_process(COMMAND "${OUT}" "${TABLE}" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the pkg-config build of the C consumer failed its run (${rc}): ${err}")
endif()
