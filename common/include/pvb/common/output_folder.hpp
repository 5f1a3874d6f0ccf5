#pragma once
// Output folders that never mix one result with another.
//
// A command that writes a folder (a recording, a run's report, a sweep)
// refuses a folder that already holds something: a second recording into
// the first one would leave the first one's images behind, named by no
// list, and its ground truth overwritten.  With --overwrite, a folder that
// pvbench made (it holds the marker file .pvbench) is emptied first; a
// folder of anything else is never emptied.
#include <string>

namespace pvb {

/// The marker file every prepared output folder holds.
inline constexpr const char* kOutputFolderMarker = ".pvbench";

/// Makes `dir` (and its parents) ready for a command's output: created when
/// missing; when it holds anything, refused (IoError naming `dir`, the
/// option to give and what is there) unless `overwrite`, and then emptied
/// if pvbench made it.  The files that are this process's own standard
/// output and error (a sweep's DIR/seed_S/stdout.log) do not count and are
/// kept.  Writes the marker, naming `command`.  The folder is locked
/// (flock) until this process ends: a second process that prepares it
/// meanwhile is refused, so two runs never write one folder.
void prepare_output_folder(const std::string& dir, bool overwrite, const std::string& command);

/// What prepare_output_folder() would refuse, checked without creating or
/// removing anything: for a command that reads its inputs first and must
/// not do its work only to fail at the output (a folder another process
/// holds included).
void check_output_folder(const std::string& dir, bool overwrite);

}  // namespace pvb
