# cmake -DBUILD_DIR= -DCONFIG= -DSOURCE_DIR= -DWORK_DIR= -DGENERATOR= -DMAKE_PROGRAM=
#       -DCXX_COMPILER= [-DCXX_FLAGS=] -P run_consumer.cmake
# Installs the sac package from BUILD_DIR into WORK_DIR/prefix, then configures, builds and
# runs the consumer project in SOURCE_DIR against it with the same compiler and flags.
function(step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    list(JOIN ARGN " " cmd)
    message(FATAL_ERROR "consumer test: failed (${rc}): ${cmd}")
  endif()
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
set(build ${WORK_DIR}/build)

step(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix} --config ${CONFIG})
step(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${build} -G ${GENERATOR}
  -DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM}
  -DCMAKE_BUILD_TYPE=${CONFIG}
  -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
  "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}"
  "-DCMAKE_EXE_LINKER_FLAGS=${CXX_FLAGS}"
  -DCMAKE_PREFIX_PATH=${prefix}
  -DCMAKE_FIND_PACKAGE_NO_PACKAGE_REGISTRY=ON)
step(${CMAKE_COMMAND} --build ${build} --config ${CONFIG})

file(GLOB_RECURSE exe LIST_DIRECTORIES false ${build}/sac_consumer ${build}/sac_consumer.exe)
if(NOT exe)
  message(FATAL_ERROR "consumer test: sac_consumer was not built")
endif()
list(GET exe 0 exe)
step(${exe})
message(STATUS "consumer test: find_package(sac) + sac::runtime OK (${exe})")
