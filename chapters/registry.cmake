# The chapter registry is generated: every directory chapters/NN_name/ with a stepper.hpp is
# a chapter, found by the build, so adding a chapter (or a variant, ./tutorial.sh variant)
# edits no list. The convention it reads (chapters/README.md):
#   stepper.hpp   declares the stepper inside `namespace fem::<ns> {` as
#                 `class <Name> [final] : public Stepper` (chapters 01-07) or as a recipe's step,
#                 `using <Name> = ch08::StepOf<Recipe>;` (chapter 08 on), constructible from
#                 (Scene, SolverSettings);
#   README.md     starts with `# Chapter NN: <title>`, the title the apps and the results show;
#   variant_of    (variants only) one line, the id of the chapter it was copied from;
#   course_files  (optional) the folder's .cpp files that are the course's, one a line: the
#                 measurements behind the lesson (lesson.cpp), the work counts (work.cpp) and
#                 alternatives no stepper runs. They compile into fem_chapters; every other .cpp
#                 of the folder into fem_steppers, the library;
#   lesson.hpp    (optional) `std::vector<Lesson> lessons();`: the course list's `lessons` hook;
#   work.hpp      (optional) count_work for its stepper: the course list's `work` hook
#                 (chapters/work.hpp).
# It writes two lists in one pass, each with what its side includes:
#   chapter_list.cpp  the steppers (id, title, make, variant_of, source hash, phase owners),
#                     chapters(): compiled into the library (fem_steppers);
#   course_list.cpp   each chapter's lessons and work hooks by id, course_chapters(): compiled
#                     into the course (fem_chapters), so the library never names a lesson.
#
# Included by CMakeLists.txt, it adds the build rule and splits the chapters' sources
# (FEM_STEPPER_SOURCES, FEM_COURSE_SOURCES); run with `cmake -P`, it writes the two lists.

if(NOT CMAKE_SCRIPT_MODE_FILE)
  file(GLOB FEM_CHAPTER_HEADERS CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/chapters/*/stepper.hpp)
  set(FEM_CHAPTER_INPUTS ${FEM_CHAPTER_HEADERS})
  foreach(header ${FEM_CHAPTER_HEADERS})
    get_filename_component(dir ${header} DIRECTORY)
    list(APPEND FEM_CHAPTER_INPUTS ${dir}/README.md)
    if(EXISTS ${dir}/lesson.hpp)
      list(APPEND FEM_CHAPTER_INPUTS ${dir}/lesson.hpp)
    endif()
    if(EXISTS ${dir}/variant_of)
      list(APPEND FEM_CHAPTER_INPUTS ${dir}/variant_of)
    endif()
  endforeach()
  # Every source of a chapter is an input: the registry records a hash of each chapter's
  # sources (a run's JSON names the code it measured), so an edit regenerates it.
  file(GLOB FEM_CHAPTER_FILES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/chapters/*/*.cpp
       ${CMAKE_CURRENT_SOURCE_DIR}/chapters/*/*.hpp)
  list(APPEND FEM_CHAPTER_INPUTS ${FEM_CHAPTER_FILES})
  # A variant_of file added later is seen: the glob reruns the configuration.
  file(GLOB FEM_CHAPTER_VARIANT_FILES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/chapters/*/variant_of)
  # The split: the .cpp files a folder's course_files names go to the course, the rest to the
  # library. A listed file that is not one of the folder's .cpp files stops the configuration
  # (a typo would otherwise ship the file in the library). Editing a list reconfigures.
  file(GLOB FEM_STEPPER_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/chapters/*/*.cpp)
  set(FEM_COURSE_SOURCES "")
  file(GLOB FEM_COURSE_LISTS CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/chapters/*/course_files)
  foreach(list_file ${FEM_COURSE_LISTS})
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${list_file})
    get_filename_component(dir ${list_file} DIRECTORY)
    file(STRINGS ${list_file} names)
    foreach(name ${names})
      string(STRIP "${name}" name)
      if(name STREQUAL "" OR name MATCHES "^#")
        continue()
      endif()
      if(NOT name MATCHES "^[^/]+\\.cpp$" OR NOT EXISTS ${dir}/${name})
        message(FATAL_ERROR "${list_file}: '${name}' is not a .cpp file of its folder "
                            "(the convention: chapters/README.md)")
      endif()
      list(APPEND FEM_COURSE_SOURCES ${dir}/${name})
    endforeach()
  endforeach()
  list(REMOVE_ITEM FEM_STEPPER_SOURCES ${FEM_COURSE_SOURCES})
  set(FEM_CHAPTER_REGISTRY ${CMAKE_CURRENT_BINARY_DIR}/generated/chapter_list.cpp)
  set(FEM_COURSE_REGISTRY ${CMAKE_CURRENT_BINARY_DIR}/generated/course_list.cpp)
  # The set of chapters is part of the command line: Ninja reruns a command whose line
  # changed, so a removed chapter (whose files are no longer inputs) regenerates the list too.
  set(FEM_CHAPTER_SET "")
  foreach(header ${FEM_CHAPTER_HEADERS})
    get_filename_component(dir ${header} DIRECTORY)
    get_filename_component(dir ${dir} NAME)
    string(APPEND FEM_CHAPTER_SET "${dir},")
  endforeach()
  add_custom_command(
    OUTPUT ${FEM_CHAPTER_REGISTRY} ${FEM_COURSE_REGISTRY}
    COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${CMAKE_CURRENT_SOURCE_DIR} -DCHAPTER_SET=${FEM_CHAPTER_SET}
            -DOUTPUT=${FEM_CHAPTER_REGISTRY} -DCOURSE_OUTPUT=${FEM_COURSE_REGISTRY}
            -P ${CMAKE_CURRENT_SOURCE_DIR}/chapters/registry.cmake
    DEPENDS ${FEM_CHAPTER_INPUTS} ${CMAKE_CURRENT_SOURCE_DIR}/chapters/registry.cmake
    COMMENT "Generating the chapter registry and the course list from chapters/*/stepper.hpp"
    VERBATIM)
  return()
endif()

function(fem_fail dir message)
  message(FATAL_ERROR "chapters/${dir}: ${message} (the convention: chapters/README.md)")
endfunction()

# The hash of a chapter's sources, as fem-tools course handin computes it: SHA-256 of the
# lines "<file> <SHA-256 of the file>\n" of its .cpp and .hpp files, sorted by name.
function(fem_source_hash out dir)
  file(GLOB sources RELATIVE ${SOURCE_DIR}/chapters/${dir} ${SOURCE_DIR}/chapters/${dir}/*.cpp
       ${SOURCE_DIR}/chapters/${dir}/*.hpp)
  list(SORT sources)
  set(manifest "")
  foreach(source ${sources})
    file(SHA256 ${SOURCE_DIR}/chapters/${dir}/${source} hash)
    string(APPEND manifest "${source} ${hash}\n")
  endforeach()
  string(SHA256 hash "${manifest}")
  set(${out} ${hash} PARENT_SCOPE)
endfunction()

# C++ string literal of a text.
function(fem_cpp_string out text)
  string(REPLACE "\\" "\\\\" text "${text}")
  string(REPLACE "\"" "\\\"" text "${text}")
  set(${out} "\"${text}\"" PARENT_SCOPE)
endfunction()

file(GLOB headers RELATIVE ${SOURCE_DIR}/chapters ${SOURCE_DIR}/chapters/*/stepper.hpp)
list(SORT headers)
set(includes "")
set(entries "")
set(course_includes "")
set(course_entries "")
foreach(header ${headers})
  get_filename_component(dir ${header} DIRECTORY)
  if(NOT dir MATCHES "^[0-9][0-9]_[A-Za-z0-9_]+$")
    fem_fail(${dir} "a chapter directory is named NN_name (two digits, then letters, digits, _)")
  endif()
  file(READ ${SOURCE_DIR}/chapters/${header} text)
  if(NOT text MATCHES "namespace fem::([A-Za-z_][A-Za-z0-9_]*) {")
    fem_fail(${dir} "stepper.hpp has no `namespace fem::<name> {`")
  endif()
  set(ns ${CMAKE_MATCH_1})
  # The chapter's stepper: a class `class <Name> [final] : public ...Stepper` (chapters 01-07) or
  # a recipe's step `using <Name> = [ch08::]StepOf<Recipe>;` (chapter 08 on).
  string(REGEX MATCHALL "class[ \t\r\n]+[A-Za-z_][A-Za-z0-9_]*[ \t\r\n]+(final[ \t\r\n]+)?:[ \t\r\n]*public[ \t\r\n]+(fem::)?([A-Za-z_][A-Za-z0-9_]*::)?[A-Za-z0-9_]*Stepper[^A-Za-z0-9_]"
         steppers "${text}")
  string(REGEX MATCHALL "using[ \t\r\n]+[A-Za-z_][A-Za-z0-9_]*[ \t\r\n]*=[ \t\r\n]*([A-Za-z_][A-Za-z0-9_]*::)?StepOf<"
         recipes "${text}")
  list(APPEND steppers ${recipes})
  list(LENGTH steppers count)
  if(NOT count EQUAL 1)
    fem_fail(${dir} "stepper.hpp declares ${count} steppers (`class <Name> [final] : public Stepper` or `using <Name> = StepOf<Recipe>;`), not one")
  endif()
  string(REGEX REPLACE "^(class|using)[ \t\r\n]+([A-Za-z0-9_]+).*" "\\2" class "${steppers}")
  file(STRINGS ${SOURCE_DIR}/chapters/${dir}/README.md heading LIMIT_COUNT 1)
  if(NOT heading MATCHES "^# Chapter [^:]+: (.+)$")
    fem_fail(${dir} "README.md does not start with `# Chapter NN: <title>`")
  endif()
  string(STRIP "${CMAKE_MATCH_1}" title)
  set(variant_of "")
  if(EXISTS ${SOURCE_DIR}/chapters/${dir}/variant_of)
    file(STRINGS ${SOURCE_DIR}/chapters/${dir}/variant_of variant_of LIMIT_COUNT 1)
    string(STRIP "${variant_of}" variant_of)
    if(NOT EXISTS ${SOURCE_DIR}/chapters/${variant_of}/stepper.hpp)
      fem_fail(${dir} "variant_of names '${variant_of}', which is no chapter")
    endif()
  endif()
  fem_cpp_string(title_literal "${title}")
  string(APPEND includes "#include \"chapters/${header}\"\n")
  fem_source_hash(source_hash ${dir})
  string(APPEND entries "      chapter<fem::${ns}::${class}>(\"${dir}\", ${title_literal}, \"${variant_of}\",\n"
                        "                                    \"${source_hash}\"),\n")
  # The course's side: the lesson measurements (lesson.hpp: `std::vector<Lesson> lessons();` in
  # its namespace) and the work counts (work.hpp: `count_work(const <Stepper>&, const Scene&,
  # const WorkCounts&)`, found by argument-dependent lookup for the stepper).
  string(APPEND course_includes "#include \"chapters/${header}\"\n")
  set(lessons "nullptr")
  if(EXISTS ${SOURCE_DIR}/chapters/${dir}/lesson.hpp)
    string(APPEND course_includes "#include \"chapters/${dir}/lesson.hpp\"\n")
    set(lessons "&fem::${ns}::lessons")
  endif()
  if(EXISTS ${SOURCE_DIR}/chapters/${dir}/work.hpp)
    string(APPEND course_includes "#include \"chapters/${dir}/work.hpp\"\n")
  endif()
  string(APPEND course_entries "      course<fem::${ns}::${class}>(\"${dir}\", ${lessons}),\n")
endforeach()
if(entries STREQUAL "")
  message(FATAL_ERROR "no chapters/*/stepper.hpp found")
endif()

# Rewritten only when it changes, so that a rebuild recompiles nothing it need not.
function(fem_write path content)
  set(old "")
  if(EXISTS ${path})
    file(READ ${path} old)
  endif()
  if(NOT "${old}" STREQUAL "${content}")
    file(WRITE ${path} "${content}")
  endif()
endfunction()

fem_write(${OUTPUT} "// Generated by chapters/registry.cmake from chapters/*/stepper.hpp, README.md and
// variant_of at build time: do not edit (add a chapter directory instead). The steppers only:
// the course's hooks are in course_list.cpp.
#include <memory>
#include <vector>

#include \"chapters/registry.hpp\"
${includes}
namespace fem::detail {

namespace {

template <class ChapterStepper>
ChapterInfo chapter(std::string id, std::string title, std::string variant_of,
                    std::string source_hash) {
  return {std::move(id), std::move(title),
          [](const Scene& scene, const SolverSettings& s) {
            return std::unique_ptr<Stepper>(std::make_unique<ChapterStepper>(scene, s));
          },
          std::move(variant_of), std::move(source_hash), owners_of<ChapterStepper>()};
}

}  // namespace

std::vector<ChapterInfo> discovered_chapters() {
  return {
${entries}  };
}

}  // namespace fem::detail
")

fem_write(${COURSE_OUTPUT} "// Generated by chapters/registry.cmake from chapters/*/stepper.hpp, lesson.hpp and work.hpp
// at build time: do not edit (add a chapter directory instead). The course's hooks of each
// chapter, by the id of its stepper in the registry (chapter_list.cpp).
#include <vector>

#include \"chapters/course.hpp\"
${course_includes}
namespace fem::detail {

namespace {

template <class ChapterStepper>
CourseHooks course(std::string id, std::vector<Lesson> (*lessons)()) {
  return {std::move(id), lessons, work_of<ChapterStepper>()};
}

}  // namespace

std::vector<CourseHooks> discovered_course() {
  return {
${course_entries}  };
}

}  // namespace fem::detail
")
