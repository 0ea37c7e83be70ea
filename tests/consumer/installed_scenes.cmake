# cmake -DPREFIX=<install> -DBUILD_RDYN=<build-tree rdyn> -DWORK_DIR=<folder> -P installed_scenes.cmake
# An installed rdyn finds shipped scenes by name in its own share/rdyn/scenes: a scene that
# exists only there is found by the installed binary and not by the build-tree one (which
# looks in the source folder).
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
set(scenes "${PREFIX}/share/rdyn/scenes")
file(READ "${scenes}/fourbar.yaml" text)
file(WRITE "${scenes}/installed-only-fourbar.yaml" "${text}")
execute_process(COMMAND ${CMAKE_COMMAND} -E env --unset=RDYN_SCENES_DIR "${PREFIX}/bin/rdyn" extract installed-only-fourbar --grid-deg 90
  --out "${WORK_DIR}/installed.csv" RESULT_VARIABLE rc_installed ERROR_VARIABLE err_installed)
execute_process(COMMAND ${CMAKE_COMMAND} -E env --unset=RDYN_SCENES_DIR "${BUILD_RDYN}" extract installed-only-fourbar --grid-deg 90
  --out "${WORK_DIR}/build.csv" RESULT_VARIABLE rc_build ERROR_VARIABLE err_build)
file(REMOVE "${scenes}/installed-only-fourbar.yaml")
if(NOT rc_installed EQUAL 0)
  message(FATAL_ERROR "the installed rdyn did not find a scene of its share/rdyn/scenes: ${err_installed}")
endif()
if(NOT rc_build EQUAL 2 OR NOT err_build MATCHES "no such scene file")
  message(FATAL_ERROR "the build-tree rdyn found an installed-only scene (exit ${rc_build}): ${err_build}")
endif()
