# Helpers shared by every src/<capability>/CMakeLists.txt, so each stays a few lines.

set(CLOTHWIND_SRC_DIR ${CMAKE_CURRENT_LIST_DIR}/../src)
get_filename_component(CLOTHWIND_SRC_DIR ${CLOTHWIND_SRC_DIR} ABSOLUTE)
set(CLOTHWIND_TEST_RESULTS ${CMAKE_BINARY_DIR}/test_results/clothwind)

# The main() of every GoogleTest binary: gtest's, plus exit code 77 (CTest: "Skipped") when all
# its tests skipped themselves (tests/gtest_main.cc).
set(CLOTHWIND_GTEST_SKIP_CODE 77)
if(NOT TARGET clothwind_gtest_main)
  add_library(clothwind_gtest_main STATIC ${CMAKE_CURRENT_LIST_DIR}/../tests/gtest_main.cc)
  target_link_libraries(clothwind_gtest_main PUBLIC GTest::gtest)
  if(CLOTHWIND_SANITIZE MATCHES "thread")  # tests/gtest_main.cc runs oneTBB serially under TSan
    target_link_libraries(clothwind_gtest_main PUBLIC TBB::tbb)
  endif()
endif()

# clothwind_capability(<cap> [DEPS <targets...>] [TEST_DEPS <targets...>])
#
# Builds library clothwind_<cap> from src/<cap>/*.cc (all but *_test.cc) and one GoogleTest
# binary per src/<cap>/*_test.cc (cartographer style: foo.h, foo.cc, foo_test.cc side by side),
# each registered with CTest. Headers are included as "<cap>/foo.h".
function(clothwind_capability cap)
  cmake_parse_arguments(C "" "" "DEPS;TEST_DEPS" ${ARGN})
  file(GLOB _all CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cc)
  set(_lib_sources "")
  set(_test_sources "")
  foreach(f ${_all})
    if(f MATCHES "_test\\.cc$")
      list(APPEND _test_sources ${f})
    else()
      list(APPEND _lib_sources ${f})
    endif()
  endforeach()
  if(_lib_sources)
    add_library(clothwind_${cap} ${_lib_sources})
    target_include_directories(clothwind_${cap} PUBLIC ${CLOTHWIND_SRC_DIR})
    target_link_libraries(clothwind_${cap} PUBLIC ${C_DEPS})
    install(TARGETS clothwind_${cap} LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
                                     ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
  else()  # headers only (so far)
    add_library(clothwind_${cap} INTERFACE)
    target_include_directories(clothwind_${cap} INTERFACE ${CLOTHWIND_SRC_DIR})
    target_link_libraries(clothwind_${cap} INTERFACE ${C_DEPS})
  endif()
  foreach(t ${_test_sources})
    get_filename_component(_name ${t} NAME_WE)
    set(_target ${cap}_${_name})
    add_executable(${_target} ${t})
    target_link_libraries(${_target} PRIVATE clothwind_${cap} ${C_TEST_DEPS} GTest::gmock clothwind_gtest_main)
    add_test(NAME ${_target}
             COMMAND ${_target} --gtest_output=xml:${CLOTHWIND_TEST_RESULTS}/${_target}.xml)
    set_tests_properties(${_target} PROPERTIES
      LABELS "unit;${cap}"
      SKIP_RETURN_CODE ${CLOTHWIND_GTEST_SKIP_CODE}
      ENVIRONMENT "CLOTHWIND_SOURCE_DIR=${CMAKE_SOURCE_DIR};CLOTHWIND_SHARED_DIR=${CMAKE_SOURCE_DIR}/../shared")
  endforeach()
endfunction()
