# pdvo_add_library(NAME <name> SRCS <files> [PUBLIC_LINK <libs>] [PRIVATE_LINK <libs>])
# Builds pdvo_<name> (also named pdvo::<name>, as other projects see it after find_package(pdvo)) from
# <name>/src, with public headers in <name>/include, installed with the export set pdvoTargets; and its tests
# from tests/<name>/.
function(pdvo_add_library)
  cmake_parse_arguments(ARG "" "NAME" "SRCS;PUBLIC_LINK;PRIVATE_LINK" ${ARGN})
  set(target pdvo_${ARG_NAME})
  add_library(${target} STATIC ${ARG_SRCS})
  add_library(pdvo::${ARG_NAME} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${ARG_NAME})
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
                                              $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${target} PUBLIC ${ARG_PUBLIC_LINK} PRIVATE ${ARG_PRIVATE_LINK})
  install(TARGETS ${target} EXPORT pdvoTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  # The library's tests live in tests/<name>/.
  if(PDVO_BUILD_TESTS AND EXISTS ${CMAKE_SOURCE_DIR}/tests/${ARG_NAME}/CMakeLists.txt)
    add_subdirectory(${CMAKE_SOURCE_DIR}/tests/${ARG_NAME} ${CMAKE_BINARY_DIR}/tests/${ARG_NAME})
  endif()
endfunction()

# pdvo_add_test(LIB <lib> NAME <unit> [LINK <libs>] [LABELS <labels>] [SLOW <gtest filter>])
# One gtest executable per tests/<lib>/<unit>_test.cpp, registered as "<lib>/<unit>_test.*", labelled unit (or
# LABELS); the tests that SLOW matches (end-to-end runs of many seconds) are labelled e2e instead, so that
# `ctest -L unit` stays fast.
function(pdvo_add_test)
  cmake_parse_arguments(ARG "" "LIB;NAME;SLOW" "LINK;LABELS" ${ARGN})
  if(NOT PDVO_BUILD_TESTS)
    return()
  endif()
  set(target ${ARG_LIB}_${ARG_NAME}_test)
  add_executable(${target} ${CMAKE_SOURCE_DIR}/tests/${ARG_LIB}/${ARG_NAME}_test.cpp)
  target_link_libraries(${target} PRIVATE ${ARG_LINK} pdvo_test_support GTest::gtest GTest::gtest_main)
  set(labels unit)
  if(ARG_LABELS)
    set(labels ${ARG_LABELS})
  endif()
  set(prefix "${ARG_LIB}/${ARG_NAME}_test.")
  if(ARG_SLOW)
    gtest_discover_tests(${target} TEST_PREFIX "${prefix}" TEST_FILTER "-${ARG_SLOW}" PROPERTIES LABELS "${labels}"
                         DISCOVERY_TIMEOUT 60)
    gtest_discover_tests(${target} TEST_PREFIX "${prefix}" TEST_FILTER "${ARG_SLOW}" PROPERTIES LABELS e2e
                         DISCOVERY_TIMEOUT 60)
  else()
    gtest_discover_tests(${target} TEST_PREFIX "${prefix}" PROPERTIES LABELS "${labels}" DISCOVERY_TIMEOUT 60)
  endif()
endfunction()
