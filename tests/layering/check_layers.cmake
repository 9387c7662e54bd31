# Proves that the layers of cmake/layers.cmake hold. For each layer, a scratch
# source is compiled with that layer's include root: it checks that a header
# of its own layer is visible (__has_include), then includes a header of the
# next layer up, which must fail to compile with "No such file or directory".
# The preprocessor stops at the missing file, so each check takes a moment.
# Run by ctest (layering.upward_include_fails) with:
#   -DCXX=<compiler> -DLAYERS_DIR=<build>/layers -DWORK_DIR=<scratch>
#   -DLAYERS="core;geometry;..." -DHEADERS="<one header per layer>"
file(MAKE_DIRECTORY ${WORK_DIR})
list(LENGTH LAYERS count)
math(EXPR last "${count} - 1")
math(EXPR below_last "${count} - 2")
set(failures 0)
foreach(i RANGE 0 ${below_last})
  list(GET LAYERS ${i} layer)
  list(GET HEADERS ${i} own)
  math(EXPR next "${i} + 1")
  list(GET HEADERS ${next} upper)
  set(source ${WORK_DIR}/${layer}.cpp)
  file(WRITE ${source} "#if !__has_include(\"${own}\")\n#error own layer header not visible\n#endif\n"
                       "#include \"${upper}\"\nint main() { return 0; }\n")
  execute_process(COMMAND ${CXX} -std=c++20 -fsyntax-only -I${LAYERS_DIR}/${layer} ${source}
                  RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(result EQUAL 0)
    message(SEND_ERROR "layer ${layer}: the upward include of ${upper} compiled")
    math(EXPR failures "${failures} + 1")
  elseif(err MATCHES "own layer header not visible")
    message(SEND_ERROR "layer ${layer}: its own header ${own} is not visible at its root")
    math(EXPR failures "${failures} + 1")
  elseif(NOT err MATCHES "${upper}: No such file or directory")
    message(SEND_ERROR "layer ${layer}: the upward include of ${upper} failed for another reason:\n${err}")
    math(EXPR failures "${failures} + 1")
  else()
    message(STATUS "layer ${layer}: sees ${own}; #include \"${upper}\" refused, as it must be")
  endif()
endforeach()
if(failures GREATER 0)
  message(FATAL_ERROR "${failures} layering check(s) failed")
endif()
