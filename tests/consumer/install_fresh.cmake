# cmake -DBUILD_DIR=<rdyn build> -DPREFIX=<folder> -DCONSUMER_BUILD=<folder> -P install_fresh.cmake
# Installs rdyn into an emptied PREFIX, so the consumer sees only what the install provides,
# and empties the consumer's build folder, so it is configured from scratch against it.
file(REMOVE_RECURSE "${PREFIX}" "${CONSUMER_BUILD}")
execute_process(COMMAND ${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${PREFIX}"
  RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install ${BUILD_DIR} --prefix ${PREFIX} failed (${rc})")
endif()
foreach(f bin/rdyn include/rdyn/reduced/runtime.hpp include/rdyn/reduced/rdyn_reduced.h
          share/rdyn/scenes/bicycle.yaml)
  if(NOT EXISTS "${PREFIX}/${f}")
    message(FATAL_ERROR "the install lacks ${f}")
  endif()
endforeach()
