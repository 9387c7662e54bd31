# Installs proxima from a build tree into a fresh prefix, configures and
# builds tests/consumer against it with find_package(proxima CONFIG), and
# runs the consumer: once on proxima::proxima alone with TBB and the
# readers' parser hidden (Eigen is all it may need), once with proxima::io. Run as a CTest test:
#   cmake -DPROXIMA_BINARY_DIR=<build> -DCONSUMER_SOURCE_DIR=<tests/consumer>
#         -DWORK_DIR=<scratch> -DGENERATOR=<gen> -DCXX_COMPILER=<c++>
#         -DCXX_FLAGS=<flags> -DLINKER_FLAGS=<flags> -DBUILD_TYPE=<type>
#         -P run_consumer.cmake
# The compiler and its flags are the build tree's, so that a sanitizer build
# (whose static libraries need the sanitizer runtime) links the consumer with
# the same runtime.
foreach(var PROXIMA_BINARY_DIR CONSUMER_SOURCE_DIR WORK_DIR GENERATOR CXX_COMPILER)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_consumer.cmake: -D${var}=... is required")
  endif()
endforeach()

function(run step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "consumer test: ${step} failed (${result}): ${ARGN}")
  endif()
endfunction()

# A fresh prefix every run: a stale install must not hide a broken one.
file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
run(install ${CMAKE_COMMAND} --install "${PROXIMA_BINARY_DIR}" --prefix "${prefix}"
    --component proxima_development)
# The installed headers include none of the private dependencies.
file(GLOB_RECURSE headers "${prefix}/include/proxima/*")
foreach(header IN LISTS headers)
  file(STRINGS "${header}" private_includes REGEX "#[ \t]*include[ \t]*[<\"](tbb/|oneapi/|libqhull|tiny_obj)")
  if(private_includes)
    message(FATAL_ERROR "consumer test: ${header} includes a private dependency: ${private_includes}")
  endif()
endforeach()

# 1. proxima::proxima alone, with TBB and the readers' parser hidden
#    from find_package: the package must need Eigen only.
# 2. proxima::proxima and proxima::io.
# 3. proxima::robot (find_package with COMPONENTS robot), on the Panda's
#    URDF given by -DROBOT_DIR (skipped without it).
set(common_args "-DCMAKE_PREFIX_PATH=${prefix}" "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}"
    "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${LINKER_FLAGS}"
    "-DCMAKE_BUILD_TYPE=${BUILD_TYPE}"
    -DCMAKE_DISABLE_FIND_PACKAGE_TBB=ON)
set(variants core io)
if(DEFINED ROBOT_DIR AND EXISTS "${prefix}/lib/cmake/proxima/proximaRobotTargets.cmake")
  list(APPEND variants robot)
endif()
foreach(variant IN LISTS variants)
  set(build "${WORK_DIR}/build-${variant}")
  set(run_args)
  if(variant STREQUAL "core")
    set(variant_args -DCONSUMER_WITH_IO=OFF)
  elseif(variant STREQUAL "io")
    set(variant_args -DCONSUMER_WITH_IO=ON)
  else()
    set(variant_args -DCONSUMER_WITH_ROBOT=ON)
    set(run_args "${ROBOT_DIR}")
  endif()
  run("configure (${variant})" ${CMAKE_COMMAND} -S "${CONSUMER_SOURCE_DIR}" -B "${build}" -G "${GENERATOR}"
      ${common_args} ${variant_args})
  run("build (${variant})" ${CMAKE_COMMAND} --build "${build}")
  run("run (${variant})" "${build}/consumer" ${run_args})
endforeach()
message(STATUS "consumer test: installed proxima found, built and run (${variants})")
