# Configures and builds tests/fuzz/project with clang (run by the fuzz_build CTest).
#   cmake -DSOURCE=<tests/fuzz/project> -DBINARY=<folder> -DCXX=<clang++> [-DJOBS=2] -P build_fuzzers.cmake
find_program(_cxx NAMES ${CXX})
if(NOT _cxx)
  message(FATAL_ERROR "${CXX} not found: the fuzz targets need clang and libFuzzer (Debian: apt-get install clang-14 libclang-rt-14-dev)")
endif()
if(NOT JOBS)
  set(JOBS 2)
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE} -B ${BINARY} -G Ninja -DCMAKE_CXX_COMPILER=${_cxx}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the fuzz targets failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${BINARY} -j ${JOBS} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building the fuzz targets failed")
endif()
