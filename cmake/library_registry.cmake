# The library's chapter list: the registry's generated list (chapters/registry.cmake) without
# each chapter's lessons and work counts, so that a program on femcourse::simulator links the
# steppers and not the course's measurements (their lesson*.cpp, work*.cpp and what those use:
# JSON, the command line, the machine record). Derived from the full list by text, so that
# whatever the registry's generator writes, the two lists name the same chapters; a change of
# its output that this no longer recognizes fails the build here, saying so.
#
# The definition is weak: a program that links fem_chapters (the course's) gets the full list,
# whose object the -u option below takes first.
#
# Included by CMakeLists.txt, it adds the build rule; run with `cmake -P`, it writes the file.
if(NOT CMAKE_SCRIPT_MODE_FILE)
  set(FEM_LIBRARY_REGISTRY ${CMAKE_CURRENT_BINARY_DIR}/generated/library_chapter_list.cpp)
  set(FEM_FULL_REGISTRY_SYMBOL _ZN3fem6detail19discovered_chaptersEv)
  add_custom_command(
    OUTPUT ${FEM_LIBRARY_REGISTRY}
    COMMAND ${CMAKE_COMMAND} -DINPUT=${FEM_CHAPTER_REGISTRY} -DOUTPUT=${FEM_LIBRARY_REGISTRY}
            -P ${CMAKE_CURRENT_SOURCE_DIR}/cmake/library_registry.cmake
    DEPENDS ${FEM_CHAPTER_REGISTRY} ${CMAKE_CURRENT_SOURCE_DIR}/cmake/library_registry.cmake
    COMMENT "Deriving the library's chapter list (no lessons, no work counts)"
    VERBATIM)
  return()
endif()

file(READ ${INPUT} text)
# (what to find, what to write instead, why it must be there)
function(fem_replace regex replacement what)
  if(NOT text MATCHES "${regex}")
    message(FATAL_ERROR "cmake/library_registry.cmake: ${INPUT} has no ${what}: "
                        "the registry's generator changed, adapt this script")
  endif()
  string(REGEX REPLACE "${regex}" "${replacement}" text "${text}")
  set(text "${text}" PARENT_SCOPE)
endfunction()
fem_replace("#include \"chapters/[0-9A-Za-z_]+/lesson\\.hpp\"\n" "" "lesson.hpp include")
fem_replace("&fem::[A-Za-z0-9_]+::lessons" "nullptr" "lessons entry")
fem_replace("work_of<ChapterStepper>\\(\\)" "ChapterWork{}" "work_of<ChapterStepper>()")
fem_replace("\nstd::vector<ChapterInfo> discovered_chapters\\(\\) {"
            "\n__attribute__((weak)) std::vector<ChapterInfo> discovered_chapters() {"
            "definition of discovered_chapters()")
set(text "// Derived by cmake/library_registry.cmake: the list below without lessons nor work.\n${text}")
# Written only when it changes (as configure_file does), so that nothing recompiles for nothing.
file(CONFIGURE OUTPUT ${OUTPUT} CONTENT "${text}" @ONLY)
