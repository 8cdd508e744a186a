# cmake -DBUILD_DIR= -DCONFIG= -DSOURCE_DIR= -DWORK_DIR= -DGENERATOR= -DMAKE_PROGRAM=
#       -DCXX_COMPILER= [-DCXX_FLAGS=] -P run_consumer.cmake
# Installs the sac package from BUILD_DIR into WORK_DIR/prefix, then configures, builds and
# runs the consumer project in SOURCE_DIR against it with the same compiler and flags; then
# builds and runs the same main.cpp with the flags `pkg-config --cflags --libs dynmesh` gives
# from the installed dynmesh.pc (when pkg-config is installed).
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

# pkg-config: the same program, compiled by hand with the installed dynmesh.pc's flags.
find_program(PKG_CONFIG_EXECUTABLE NAMES pkg-config pkgconf)
if(NOT PKG_CONFIG_EXECUTABLE)
  message(STATUS "consumer test: pkg-config not found, dynmesh.pc not tested")
  return()
endif()
file(GLOB_RECURSE pc LIST_DIRECTORIES false ${prefix}/dynmesh.pc)
if(NOT pc)
  message(FATAL_ERROR "consumer test: dynmesh.pc was not installed")
endif()
get_filename_component(pc_dir ${pc} DIRECTORY)
execute_process(COMMAND ${CMAKE_COMMAND} -E env PKG_CONFIG_PATH=${pc_dir}
                        ${PKG_CONFIG_EXECUTABLE} --cflags --libs dynmesh
                OUTPUT_VARIABLE pc_flags OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "consumer test: pkg-config --cflags --libs dynmesh failed (${rc})")
endif()
separate_arguments(pc_flags UNIX_COMMAND "${pc_flags}")
separate_arguments(extra_flags UNIX_COMMAND "${CXX_FLAGS}")
step(${CXX_COMPILER} ${extra_flags} ${SOURCE_DIR}/main.cpp -o ${WORK_DIR}/pc_consumer ${pc_flags})
step(${WORK_DIR}/pc_consumer)
message(STATUS "consumer test: pkg-config dynmesh OK (${pc_flags})")
