# ctest: install rdyn into a fresh prefix under the build tree, then configure, build and run
# the outside project in this folder against it with find_package(rdyn) (issue #12).
# Included by tests/CMakeLists.txt; the consumer project itself never reads this file.
set(RDYN_CONSUMER_PREFIX ${CMAKE_BINARY_DIR}/consumer/prefix)
set(RDYN_CONSUMER_BUILD ${CMAKE_BINARY_DIR}/consumer/build)
set(RDYN_CONSUMER_DIR ${CMAKE_CURRENT_LIST_DIR})

# The same compilers and flags as rdyn (a sanitized rdyn needs sanitized consumers).
include(CheckLanguage)
check_language(C)
set(consumer_flags)
if(RDYN_SANITIZE)
  set(san "-fsanitize=address,undefined -fno-omit-frame-pointer")
  list(APPEND consumer_flags "-DCMAKE_C_FLAGS=${san}" "-DCMAKE_CXX_FLAGS=${san}"
    "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined")
endif()
if(CMAKE_C_COMPILER)
  list(APPEND consumer_flags "-DCMAKE_C_COMPILER=${CMAKE_C_COMPILER}")
endif()

add_test(NAME consumer.install
  COMMAND ${CMAKE_COMMAND} -DBUILD_DIR=${CMAKE_BINARY_DIR} -DPREFIX=${RDYN_CONSUMER_PREFIX}
          -DCONSUMER_BUILD=${RDYN_CONSUMER_BUILD} -P ${RDYN_CONSUMER_DIR}/install_fresh.cmake)
set_tests_properties(consumer.install PROPERTIES FIXTURES_SETUP rdyn_prefix TIMEOUT 120)

add_test(NAME consumer.installed_scenes
  COMMAND ${CMAKE_COMMAND} -DPREFIX=${RDYN_CONSUMER_PREFIX} -DBUILD_RDYN=$<TARGET_FILE:rdyn>
          -DWORK_DIR=${CMAKE_BINARY_DIR}/consumer/scenes -P ${RDYN_CONSUMER_DIR}/installed_scenes.cmake)
set_tests_properties(consumer.installed_scenes PROPERTIES FIXTURES_REQUIRED rdyn_prefix TIMEOUT 120)

add_test(NAME consumer.configure
  COMMAND ${CMAKE_COMMAND} -G ${CMAKE_GENERATOR} -S ${RDYN_CONSUMER_DIR} -B ${RDYN_CONSUMER_BUILD}
          -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${RDYN_CONSUMER_PREFIX}
          -DCMAKE_CXX_COMPILER=${CMAKE_CXX_COMPILER} ${consumer_flags})
set_tests_properties(consumer.configure PROPERTIES FIXTURES_REQUIRED rdyn_prefix
  FIXTURES_SETUP consumer_configured TIMEOUT 120)

add_test(NAME consumer.build COMMAND ${CMAKE_COMMAND} --build ${RDYN_CONSUMER_BUILD})
set_tests_properties(consumer.build PROPERTIES FIXTURES_REQUIRED "rdyn_prefix;consumer_configured"
  FIXTURES_SETUP consumer_built TIMEOUT 300)

# The table comes from the installed CLI, the scene found by name.
add_test(NAME consumer.extract
  COMMAND ${RDYN_CONSUMER_PREFIX}/bin/rdyn extract bicycle --out ${CMAKE_BINARY_DIR}/consumer/bicycle.csv --force)
set_tests_properties(consumer.extract PROPERTIES FIXTURES_REQUIRED rdyn_prefix FIXTURES_SETUP consumer_table
  TIMEOUT 120)

foreach(api cxx c)
  add_test(NAME consumer.cadence_${api}
    COMMAND ${RDYN_CONSUMER_BUILD}/cadence_${api} ${CMAKE_BINARY_DIR}/consumer/bicycle.csv)
  set_tests_properties(consumer.cadence_${api} PROPERTIES
    FIXTURES_REQUIRED "rdyn_prefix;consumer_built;consumer_table" TIMEOUT 120)
endforeach()

# The pkg-config file alone (plain C compiler, no CMake package); not under the sanitizers,
# whose flags pkg-config does not carry.
if(CMAKE_C_COMPILER AND NOT RDYN_SANITIZE)
  add_test(NAME consumer.pkg_config
    COMMAND ${CMAKE_COMMAND} -DPREFIX=${RDYN_CONSUMER_PREFIX} -DCC=${CMAKE_C_COMPILER}
            -DSOURCE=${RDYN_CONSUMER_DIR}/cadence_c.c -DOUT=${CMAKE_BINARY_DIR}/consumer/cadence_c_pkgconfig
            -DTABLE=${CMAKE_BINARY_DIR}/consumer/bicycle.csv -P ${RDYN_CONSUMER_DIR}/pkg_config_build.cmake)
  set_tests_properties(consumer.pkg_config PROPERTIES FIXTURES_REQUIRED "rdyn_prefix;consumer_table"
    TIMEOUT 120)
endif()
