# The layers of the library (docs/architecture.md), lowest first. Each is an
# object library built from src/<layer>/*.cpp that sees only its own layer
# and the layers before it: its include root (build/layers/<layer>) holds
# links to exactly those folders of src/, include/proxima/ and
# include/proxima/detail/, so an upward #include is a build error ("file
# not found"), not a review comment. tests/layering proves it.
set(PROXIMA_LAYERS core geometry hull shape narrowphase penetration query motion scene)

set(PROXIMA_LAYER_OBJECTS)
set(visible)
foreach(layer IN LISTS PROXIMA_LAYERS)
  list(APPEND visible ${layer})
  set(root ${PROJECT_BINARY_DIR}/layers/${layer})
  file(REMOVE_RECURSE ${root})
  file(MAKE_DIRECTORY ${root}/proxima/detail)
  foreach(seen IN LISTS visible)
    foreach(pair "src/${seen}:${seen}" "include/proxima/${seen}:proxima/${seen}"
                 "include/proxima/detail/${seen}:proxima/detail/${seen}")
      string(REPLACE ":" ";" pair "${pair}")
      list(GET pair 0 from)
      list(GET pair 1 to)
      if(EXISTS ${PROJECT_SOURCE_DIR}/${from})
        file(CREATE_LINK ${PROJECT_SOURCE_DIR}/${from} ${root}/${to} SYMBOLIC)
      endif()
    endforeach()
  endforeach()
  file(GLOB sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/${layer}/*.cpp)
  add_library(proxima_${layer} OBJECT ${sources})
  target_include_directories(proxima_${layer} PRIVATE ${root})
  target_link_libraries(proxima_${layer} PRIVATE Eigen3::Eigen TBB::tbb proxima_warnings)
  set_target_properties(proxima_${layer} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  list(APPEND PROXIMA_LAYER_OBJECTS $<TARGET_OBJECTS:proxima_${layer}>)
endforeach()
