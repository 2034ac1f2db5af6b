# Every folder of chapters/ that the build reads (one holding .cpp or .hpp files) has a name the
# build can use: NN_name, letters, digits and _. Its name goes into build.ninja, a namespace and
# a target; a name with a newline once made configure write a build.ninja that ninja could not
# lex, and every later build failed, also after the folder was gone. Configure stops here
# instead, naming the folder, before it writes anything.
#
# Included by CMakeLists.txt (before the chapter globs); run alone as a check:
#   cmake -DCHAPTERS_DIR=path/to/chapters -P cmake/chapter_names.cmake

# The name as a message shows it: control characters spelled out, so that a newline is seen.
function(fem_visible_name out name)
  string(REPLACE "\n" "\\n" name "${name}")
  string(REPLACE "\r" "\\r" name "${name}")
  string(REPLACE "\t" "\\t" name "${name}")
  set(${out} "${name}" PARENT_SCOPE)
endfunction()

function(fem_check_chapter_names chapters_dir)
  # LIST_DIRECTORIES lists every entry; a name holding ';' splits into pieces that are no
  # folder, and is reported by its first piece.
  file(GLOB entries LIST_DIRECTORIES true RELATIVE "${chapters_dir}" "${chapters_dir}/*")
  foreach(name IN LISTS entries)
    if(NOT IS_DIRECTORY "${chapters_dir}/${name}" AND EXISTS "${chapters_dir}/${name}")
      continue()  # a file of chapters/ itself (registry.cmake, README.md)
    endif()
    file(GLOB sources "${chapters_dir}/${name}/*.cpp" "${chapters_dir}/${name}/*.hpp")
    if(EXISTS "${chapters_dir}/${name}" AND NOT sources)
      continue()  # a folder the build does not read
    endif()
    if(NOT name MATCHES "^[0-9][0-9]_[A-Za-z0-9_]+$" OR NOT EXISTS "${chapters_dir}/${name}")
      fem_visible_name(shown "${name}")
      if(NOT EXISTS "${chapters_dir}/${name}")
        set(shown "${shown}... (a name holding ';')")
      endif()
      message(FATAL_ERROR
              "chapters/${shown}: a chapter folder's name is NN_name, with letters, digits and _ "
              "only (./tutorial.sh variant makes such names); rename or remove the folder, then "
              "build again")
    endif()
  endforeach()
endfunction()

if(CMAKE_SCRIPT_MODE_FILE)
  fem_check_chapter_names("${CHAPTERS_DIR}")
else()
  fem_check_chapter_names("${CMAKE_CURRENT_SOURCE_DIR}/chapters")
endif()
