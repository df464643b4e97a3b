# detslam_module(NAME DEPS ... [TEST_DEPS ...])
# Builds src/detslam/NAME/*.cc (without *_test.cc) into the library detslam_NAME, and every
# src/detslam/NAME/*_test.cc into one test binary detslam_NAME_test (ctest label "unit" unless the
# test's name starts with Data, which gets the label "data"). TEST_DEPS: what only the tests link
# besides the library (e.g. an OpenCV module the tests use and the library does not). A folder without sources yields an
# INTERFACE library so that dependants link regardless.
set(DETSLAM_WARNINGS -Wall -Wextra -Werror)

function(detslam_module name)
  cmake_parse_arguments(ARG "" "" "DEPS;TEST_DEPS" ${ARGN})
  set(dir "${CMAKE_SOURCE_DIR}/src/detslam/${name}")
  file(GLOB all_sources CONFIGURE_DEPENDS "${dir}/*.cc")
  file(GLOB test_sources CONFIGURE_DEPENDS "${dir}/*_test.cc")
  set(lib_sources ${all_sources})
  if(test_sources)
    list(REMOVE_ITEM lib_sources ${test_sources})
  endif()
  set(target detslam_${name})
  if(lib_sources)
    add_library(${target} STATIC ${lib_sources})
    target_include_directories(${target} PUBLIC "${CMAKE_SOURCE_DIR}/src")
    target_link_libraries(${target} PUBLIC ${ARG_DEPS})
    target_compile_options(${target} PRIVATE ${DETSLAM_WARNINGS})
    if(DETSLAM_FUZZ AND name IN_LIST DETSLAM_FUZZ_MODULES)
      # Coverage for libFuzzer's guidance, in the modules whose parsers the fuzz targets reach
      # only: elsewhere (rendering, extraction) it would slow the tests sharing the build 50-fold.
      target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
    endif()
  else()
    add_library(${target} INTERFACE)
    target_include_directories(${target} INTERFACE "${CMAKE_SOURCE_DIR}/src")
    target_link_libraries(${target} INTERFACE ${ARG_DEPS})
  endif()
  if(DETSLAM_BUILD_TESTS AND test_sources)
    add_executable(${target}_test ${test_sources} ${DETSLAM_TSAN_EXTRA_SOURCE})
    target_link_libraries(${target}_test PRIVATE ${target} ${ARG_TEST_DEPS} detslam_test_support
                          GTest::gmock GTest::gtest_main)
    target_compile_options(${target}_test PRIVATE ${DETSLAM_WARNINGS})
    detslam_discover_tests(${target}_test)
  endif()
endfunction()

# Registers a gtest binary with ctest: test suites named Data* (real data from ../shared) get the
# label "data", suites named Integration* the label "integration", all others "unit".
function(detslam_discover_tests target)
  gtest_discover_tests(${target} TEST_FILTER "-Data*:Integration*" PROPERTIES LABELS unit
                       DISCOVERY_TIMEOUT 60)
  gtest_discover_tests(${target} TEST_FILTER "Data*" PROPERTIES LABELS data DISCOVERY_TIMEOUT 60)
  gtest_discover_tests(${target} TEST_FILTER "Integration*" PROPERTIES LABELS integration
                       DISCOVERY_TIMEOUT 60)
endfunction()
