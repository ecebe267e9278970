# facyl_add_module(<name> SOURCES ... DEPENDS ... [PRIVATE_DEPENDS ...])
# One PCL-like library per module: headers in <name>/include/facyl/<name>/, explicit
# instantiations in <name>/src/. Exported as facyl::<name>.
#
# Every module also carries facyl::pcl_templates in its interface: what PCL's own templates
# need at link time when a user compiles them for another point type (PCL_NO_PRECOMPILE, e.g.
# pcl::PointXYZI). PCL's kd-tree headers include FLANN's, which call LZ4
# (LZ4_decompress_safe_continue), and PCL's FLANN::FLANN links flann_cpp only: a user linking
# facyl::sample_consensus_alt alone would miss liblz4. facylConfig.cmake defines the same
# target for installed copies.
include_guard(GLOBAL)

function(facyl_define_pcl_templates_target)
  if(TARGET facyl::pcl_templates)
    return()
  endif()
  find_library(FACYL_LZ4_LIBRARY NAMES lz4 DOC "LZ4, called by FLANN's headers")
  add_library(facyl::pcl_templates INTERFACE IMPORTED GLOBAL)
  if(FACYL_LZ4_LIBRARY)
    set_target_properties(facyl::pcl_templates PROPERTIES
      INTERFACE_LINK_LIBRARIES "${FACYL_LZ4_LIBRARY}")
  endif()
endfunction()
facyl_define_pcl_templates_target()

function(facyl_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPENDS;PRIVATE_DEPENDS" ${ARGN})
  set(target facyl_${name})
  add_library(${target} ${ARG_SOURCES})
  add_library(facyl::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME facyl_${name}
    VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_compile_features(${target} PUBLIC cxx_std_17)
  target_compile_options(${target} PRIVATE -Wall -Wextra)
  target_link_libraries(${target} PUBLIC ${ARG_DEPENDS} PRIVATE ${ARG_PRIVATE_DEPENDS}
    INTERFACE facyl::pcl_templates)
  install(TARGETS ${target} EXPORT facylTargets
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(DIRECTORY include/facyl DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()
