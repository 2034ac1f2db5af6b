// fem_lessons: runs the measurements behind the lessons' tables, printed as Markdown (and,
// with --readme, written between marker comments of a chapter's README, so that no number
// in a lesson is typed by hand). Each lesson's code lives in its chapter
// (chapters/NN_name/lesson.cpp); this program finds it through the chapter registry, and
// with --chapter runs a student's variant's copy beside the original's. A lesson of the whole
// course, not of one chapter (the roofline, apps/roofline/; the library's frame times,
// apps/frame_times/), is registered here.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "apps/frame_times/lesson.hpp"
#include "apps/phase_owners.hpp"
#include "apps/roofline/lesson.hpp"
#include "chapters/course.hpp"
#include "chapters/registry.hpp"
#include "common/atomic_file.hpp"
#include "common/build_info.hpp"
#include "common/cli.hpp"
#include "common/json.hpp"
#include "common/lesson.hpp"
#include "common/machine_load.hpp"
#include "common/machine_record.hpp"
#include "common/threads.hpp"

namespace {

using namespace fem;

struct Found {
  const ChapterInfo* chapter;  // null for a lesson of the whole course
  Lesson lesson;
};

// Every lesson of the course's chapters (variants aside), in chapter order, then the course's.
std::vector<Found> course_lessons() {
  std::vector<Found> found;
  for (const CourseChapter& c : course_chapters())
    if (c.lessons && c.chapter->variant_of.empty())
      for (Lesson& l : c.lessons()) found.push_back({c.chapter, std::move(l)});
  for (Lesson& l : roofline::lessons()) found.push_back({nullptr, std::move(l)});
  for (Lesson& l : frame_times::lessons()) found.push_back({nullptr, std::move(l)});
  return found;
}

std::string usage() {
  std::string out = "usage: fem_lessons [LESSON [--chapter ID] [options]]\n";
  for (const Found& f : course_lessons())
    out += "  " + f.lesson.name +
           std::string(std::max<int>(1, 17 - int(f.lesson.name.size())), ' ') +
           (f.chapter ? "chapter " + f.chapter->id.substr(0, 2) : std::string("the course")) +
           ": " + f.lesson.summary + "\n";
  return out + "without a lesson: every lesson in turn, with its defaults\n" +
         "record-all [--out DIR]: every lesson with the arguments it is recorded with, as " +
         "DIR/LESSON.json\n" +
         "phase-owners [--write FILE | --check FILE]: which part of which chapter runs each " +
         "phase of each chapter's step, from the recipes (chapters/README.md's table)\n";
}

// The lesson `name` of chapter `id` (a variant has its own copy); throws UsageError.
Lesson lesson_of(const ChapterInfo& chapter, const std::string& name) {
  if (const CourseChapter& course = course_of(chapter); course.lessons)
    for (Lesson& l : course.lessons())
      if (l.name == name) return l;
  throw UsageError("chapter " + chapter.id + " has no lesson '" + name + "'");
}

// The command line that made a table, for the JSON record.
std::string command_line(int argc, char** argv) {
  std::string out = "fem_lessons";
  for (int i = 0; i < argc; ++i) out += std::string(" ") + argv[i];
  return out;
}

// The table as committed data (docs/data/lessons/NAME.json): fem-tools docs lessons writes
// it between the lesson's markers of the chapter's README (or the lesson's own page), and
// checks that it is there. A lesson's numbers, when it leaves them, go in "data".
void write_json(const std::string& path, const Lesson& lesson, const ChapterInfo* chapter,
                const std::string& command, const std::string& table, const std::string& data) {
  const std::string id = chapter ? chapter->id : "";
  Json out = {{"schema_version", 1},
              {"lesson", lesson.name},
              {"chapter", id},
              {"readme", !lesson.readme.empty() ? lesson.readme : "chapters/" + id + "/README.md"},
              {"marker", lesson.name + "-table"},
              {"command", command},
              {"table", table}};
  Json machine = Json::object();
  add_machine_record(machine, machine_record());
  out["machine"] = std::move(machine);
  // The build and the commit, as fem_bench records them: every timed table's caption names the
  // machine, the compiler and the commit it was recorded on (fem-tools docs lessons). The
  // sources' state once per run: record-all's own JSON files, written one after another, are
  // no change to the code it measures.
  static const SourceState source = source_state();
  const BuildInfo b = build_info();
  out["build"] = {{"compiler", b.compiler}, {"flags", b.flags}, {"build_type", b.build_type}};
  add_source_state(out, source);
  if (!data.empty()) out["data"] = Json::parse(data);
  write_json_file(path, out);
}

// Fails before the work when the JSON cannot be written there.
void check_json_writable(const std::string& path) {
  try {
    check_writable(path);
  } catch (const WriteError& e) {
    throw UsageError(std::string("--json: ") + e.what());
  }
}

// The lesson's table, on one thread unless the lesson measures threads; a timed lesson's run
// on a busy machine says so under the table (and on stderr).
std::string measure(const Lesson& lesson, const LessonRun& run) {
  LoadMonitor load;
  std::string table;
  if (lesson.uses_threads) {
    table = lesson.table(run);
  } else {
    const OneThreadScope one_thread;
    table = lesson.table(run);
  }
  load.stop();
  if (!lesson.timed || !load.busy()) return table;
  std::cerr << "fem_lessons " << lesson.name << ": " << load.warning() << "\n";
  return table + "\n**Measured on a busy machine:** " + load.warning() + "\n";
}

// A lesson's chapter lists (the roofline's --chapters, --other-chapters, --alone-chapters),
// checked before any measurement as fem_bench checks its --chapters: each chapter known, none
// named twice. The roofline measured a repeated chapter twice, and refused an unknown one only
// after its roofs (about 10 s).
void check_chapter_lists(const ArgParser& args) {
  for (const std::string name : {"chapters", "other-chapters", "alone-chapters"}) {
    if (!args.has_option(name) || args.get_list(name).empty()) continue;
    try {
      find_chapters(args.get_list(name));
    } catch (const std::invalid_argument& e) {
      throw UsageError("--" + name + ": " + e.what());
    }
  }
}

// The lesson's run, and its copy in the variant --chapter names, after the original's.
std::vector<std::pair<const ChapterInfo*, Lesson>> lesson_runs(const Found& found,
                                                               const ArgParser& args) {
  std::vector<std::pair<const ChapterInfo*, Lesson>> runs = {{found.chapter, found.lesson}};
  if (const std::string id = found.chapter ? args.get("chapter") : ""; !id.empty()) {
    const ChapterInfo& variant = find_chapter(id);
    if (variant.id != found.chapter->id)
      runs.push_back({&variant, lesson_of(variant, found.lesson.name)});
  }
  return runs;
}

// Runs one lesson; argv[0] is its name. A variant's table is printed after the original's.
int run_lesson(const Found& found, int argc, char** argv) {
  const std::string program = "fem_lessons " + found.lesson.name;
  ArgParser args(program, found.lesson.summary + ". Prints the lesson's table in Markdown.");
  add_scene_options(args, found.lesson.default_mesh);
  args.option("steps", "N", "measured steps or solves", "50");
  if (found.chapter)
    args.option("chapter", "ID", "also run the lesson's copy in this variant of the chapter", "");
  args.option("readme", "FILE", "also write the table between the lesson's markers in FILE", "");
  args.option("json", "FILE", "also write the table as JSON (docs/data/lessons/NAME.json)", "");
  add_thread_option(args);
  if (found.lesson.add_options) found.lesson.add_options(args);
  return run_program(program, [&] {
    if (!args.parse(argc, argv)) return 0;
    // The program's thread count again after the lesson: record-all runs the next lesson
    // with its own --threads or none (chapter 10's is recorded with --threads 1).
    const ThreadCountScope program_threads(max_threads());
    const AskedThreadsScope program_asked(thread_count_asked());
    threads_from_args(args);
    check_chapter_lists(args);
    // The roofline's second count, held to --threads' rule before any roof (0 would run as 1).
    if (args.has_option("threads-max")) thread_counts_from_args(args, "threads-max");
    const Scene scene = scene_from_args(args);
    const int steps = args.get_int("steps");
    if (steps <= 0) throw UsageError("--steps must be positive");
    const std::vector<std::pair<const ChapterInfo*, Lesson>> runs = lesson_runs(found, args);
    const std::string& readme = args.get_nonempty("readme");
    const std::string& json = args.get_nonempty("json");
    if ((!readme.empty() || !json.empty()) && runs.size() > 1)
      throw UsageError("--readme and --json record the course's table: leave --chapter out");
    if (!json.empty()) check_json_writable(json);
    if (!readme.empty()) check_markers(readme, found.lesson.name + "-table");
    // A lesson may leave std::fixed and a precision on the streams: the next run (a
    // variant's, after the original's) starts from the streams' defaults again.
    std::ios cout_defaults(nullptr), cerr_defaults(nullptr);
    cout_defaults.copyfmt(std::cout);
    cerr_defaults.copyfmt(std::cerr);
    for (const auto& [chapter, lesson] : runs) {
      std::cout.copyfmt(cout_defaults);
      std::cerr.copyfmt(cerr_defaults);
      if (runs.size() > 1) std::cout << "\n### " << chapter->id << "\n\n";
      std::string data;
      const std::string table =
          measure(lesson, {args, scene, steps, chapter ? chapter->id : "", &data});
      std::cout << table << std::flush;
      if (!readme.empty()) {
        write_between_markers(readme, lesson.name + "-table", table);
        std::cout << "wrote " << readme << "\n";
      }
      if (!json.empty()) {
        write_json(json, lesson, chapter, command_line(argc, argv), table, data);
        std::cout << "wrote " << json << "\n";
      }
    }
    return 0;
  });
}

// The command line a lesson is recorded with: its record_args, its further meshes that exist
// added to --meshes, and --json DIR/NAME.json.
std::vector<std::string> recording_args(const Lesson& lesson, const std::string& dir) {
  std::vector<std::string> words = {lesson.name};
  words.insert(words.end(), lesson.record_args.begin(), lesson.record_args.end());
  for (const std::string& mesh : lesson.record_meshes_if_present) {
    if (!std::filesystem::exists(resolve_mesh_path(mesh))) continue;
    const auto meshes = std::find(words.begin(), words.end(), "--meshes");
    if (meshes == words.end() || meshes + 1 == words.end())
      words.insert(words.end(), {"--meshes", mesh});
    else
      *(meshes + 1) += "," + mesh;
  }
  words.insert(words.end(),
               {"--json", (std::filesystem::path(dir) / (lesson.name + ".json")).string()});
  return words;
}

// fem_lessons record-all: every lesson of the course, each as recording_args() says, so that
// no list of lessons and their arguments is kept anywhere else (./tutorial.sh lessons).
int record_all(const std::vector<Found>& lessons, int argc, char** argv) {
  const std::string program = "fem_lessons record-all";
  ArgParser args(program,
                 "Records every lesson's table with the arguments the lesson gives "
                 "(Lesson::record_args), as DIR/LESSON.json.");
  args.option("out", "DIR", "directory of the records (made if missing)", "docs/data/lessons");
  return run_program(program, [&] {
    if (!args.parse(argc, argv)) return 0;
    const std::string dir = args.get_nonempty("out");
    std::filesystem::create_directories(dir);
    for (const Found& found : lessons) {
      std::vector<std::string> words = recording_args(found.lesson, dir);
      std::vector<char*> lesson_argv;
      for (std::string& w : words) lesson_argv.push_back(w.data());
      progress("recording " + found.lesson.name + " (" + std::to_string(&found - &lessons[0] + 1) +
               " of " + std::to_string(lessons.size()) + ")");
      if (const int status = run_lesson(found, int(lesson_argv.size()), lesson_argv.data()))
        return status;
    }
    return 0;
  });
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<Found> lessons = course_lessons();
  if (argc < 2) {  // every lesson, as the README of its chapter shows it
    for (const Found& found : lessons) {
      std::cout << "\n## fem_lessons " << found.lesson.name << "\n\n" << std::flush;
      char* lesson_argv[] = {argv[0]};
      if (const int status = run_lesson(found, 1, lesson_argv); status != 0) return status;
    }
    return 0;
  }
  const std::string first = argv[1];
  if (first == "--help" || first == "-h")
    return fem::run_program("fem_lessons", [] {
      std::cout << usage() << "(fem_lessons LESSON --help for the options)\n";
      return 0;
    });
  if (first == "record-all") return record_all(lessons, argc - 1, argv + 1);
  if (first == "phase-owners") return phase_owners_command(argc - 1, argv + 1);
  const auto it = std::find_if(lessons.begin(), lessons.end(),
                               [&](const Found& f) { return f.lesson.name == first; });
  if (it == lessons.end()) {
    std::cerr << "fem_lessons: unknown lesson '" << first << "'\n" << usage();
    return 2;
  }
  return run_lesson(*it, argc - 1, argv + 1);
}
