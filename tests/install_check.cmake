# The product stands alone (issue 9): installs proxima from a build tree into
# a fresh prefix and checks that what is shipped (the `proxima` tool and the
# libraries) links none of the peers (FCL, libccd, Bullet), nor Python, and
# calls neither fork(), system() nor popen(). Before issue 9 the CLI linked
# the paper's experiments, so the installed `proxima` needed libfcl, libccd
# and Bullet and imported fork and system. Run as a CTest test:
#   cmake -DPROXIMA_BINARY_DIR=<build> -DPROXIMA_SOURCE_DIR=<source>
#         -DWORK_DIR=<scratch> -P install_check.cmake
foreach(var PROXIMA_BINARY_DIR PROXIMA_SOURCE_DIR WORK_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "install_check.cmake: -D${var}=... is required")
  endif()
endforeach()
foreach(tool ldd nm)
  find_program(PROXIMA_${tool} ${tool} REQUIRED)
endforeach()

# Libraries no shipped file may load (ldd) and symbols it may not reference
# (nm): FCL, libccd, Bullet (btVector3, btCollisionWorld, ...; the libraries
# are libBullet* and libLinearMath*), Python's C API.
set(forbidden_libraries "libfcl|libccd|libBullet|libLinearMath|libpython")
set(forbidden_symbols "fcl::|(^| )_?ccd[A-Z_]|(^| )bt[A-Z][A-Za-z]+|(^| )_?Py[A-Z_][A-Za-z_]+")
# Process creation: fork, vfork, system, popen, posix_spawn and the exec family.
set(forbidden_calls "^(fork|vfork|system|popen|posix_spawnp?|execl|execlp|execle|execv|execvp|execvpe)(@.*)?$")

set(failures "")
macro(fail message)
  string(APPEND failures "  ${message}\n")
endmacro()

file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
foreach(component proxima_runtime proxima_development)
  execute_process(COMMAND ${CMAKE_COMMAND} --install "${PROXIMA_BINARY_DIR}" --prefix "${prefix}"
                          --component ${component}
                  RESULT_VARIABLE result OUTPUT_QUIET)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "install check: cmake --install --component ${component} failed (${result})")
  endif()
endforeach()

file(GLOB_RECURSE installed LIST_DIRECTORIES false "${prefix}/bin/*" "${prefix}/lib*/*.a" "${prefix}/lib*/*.so*")
if(NOT EXISTS "${prefix}/bin/proxima")
  fail("bin/proxima was not installed")
endif()
set(libraries_seen 0)
foreach(file IN LISTS installed)
  file(RELATIVE_PATH name "${prefix}" "${file}")
  if(name MATCHES "\\.a$")
    math(EXPR libraries_seen "${libraries_seen} + 1")
    # A static library: its undefined symbols are what a consumer's link
    # must provide.
    execute_process(COMMAND ${PROXIMA_nm} --undefined-only --demangle "${file}"
                    OUTPUT_VARIABLE undefined RESULT_VARIABLE result ERROR_QUIET)
  else()
    execute_process(COMMAND ${PROXIMA_ldd} "${file}" OUTPUT_VARIABLE linked RESULT_VARIABLE result)
    if(NOT result EQUAL 0)
      fail("${name}: ldd failed (${result})")
    endif()
    string(REGEX MATCHALL "[^\n\t /]*(${forbidden_libraries})[^\n\t /]*" bad "${linked}")
    if(bad)
      list(REMOVE_DUPLICATES bad)
      fail("${name} links ${bad}")
    endif()
    execute_process(COMMAND ${PROXIMA_nm} -D --undefined-only --demangle "${file}"
                    OUTPUT_VARIABLE undefined RESULT_VARIABLE result ERROR_QUIET)
  endif()
  if(NOT result EQUAL 0)
    fail("${name}: nm failed (${result})")
    continue()
  endif()
  string(REPLACE "\n" ";" lines "${undefined}")
  foreach(line IN LISTS lines)
    # nm's line: "                 U symbol"; keep the symbol.
    string(REGEX REPLACE "^[ \t]*[A-Za-z][ \t]+" "" symbol "${line}")
    if(symbol MATCHES "${forbidden_calls}")
      fail("${name} calls ${symbol}")
    elseif(symbol MATCHES "${forbidden_symbols}")
      fail("${name} references ${symbol}")
    endif()
  endforeach()
endforeach()
if(libraries_seen EQUAL 0)
  fail("no library was installed under ${prefix}/lib*")
endif()

# The sources of what is shipped: no process creation there either (a call
# the linker dropped today would come back with the next caller).
file(GLOB_RECURSE sources "${PROXIMA_SOURCE_DIR}/src/*" "${PROXIMA_SOURCE_DIR}/cli/*"
     "${PROXIMA_SOURCE_DIR}/io/*" "${PROXIMA_SOURCE_DIR}/include/*")
foreach(source IN LISTS sources)
  if(NOT source MATCHES "\\.(h|hpp|cpp|cc)$")
    continue()
  endif()
  file(STRINGS "${source}" hits REGEX "std::system|(^|[^A-Za-z0-9_.>])(fork|vfork|popen|system|posix_spawnp?|exec[lv]p?e?)\\(")
  if(hits)
    file(RELATIVE_PATH name "${PROXIMA_SOURCE_DIR}" "${source}")
    fail("${name} mentions process creation: ${hits}")
  endif()
endforeach()

if(failures)
  message(FATAL_ERROR "install check: the shipped product is not standalone:\n${failures}")
endif()
list(LENGTH installed count)
message(STATUS "install check: ${count} installed binaries and libraries link no peer, no Python, "
               "and create no process")
