# basalt_embed(TARGET target NAMESPACE ns FILES f1 f2 ...): turns text files (shaders, the default
# show's script) into a generated source that defines `std::string_view ns::kFileName` for each.
# The files stay editable as files, and the binary needs nothing at run time.
function(basalt_embed)
  cmake_parse_arguments(ARG "" "TARGET;NAMESPACE;HEADER" "FILES" ${ARGN})
  set(out_dir ${PROJECT_BINARY_DIR}/generated/embedded)
  set(header ${out_dir}/${ARG_HEADER})
  string(REPLACE ".h" ".cpp" source ${header})
  set(script ${PROJECT_SOURCE_DIR}/cmake/embed_files.cmake)
  string(REPLACE ";" "|" files "${ARG_FILES}")
  add_custom_command(
    OUTPUT ${header} ${source}
    COMMAND ${CMAKE_COMMAND} -DHEADER=${header} -DSOURCE=${source} -DNAMESPACE=${ARG_NAMESPACE}
            -DFILES=${files} -P ${script}
    DEPENDS ${ARG_FILES} ${script}
    COMMENT "Embedding ${ARG_HEADER}"
    VERBATIM)
  target_sources(${ARG_TARGET} PRIVATE ${source} ${header})
endfunction()
