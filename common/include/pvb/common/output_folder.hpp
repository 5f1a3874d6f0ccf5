#pragma once
// Output folders that never mix one result with another.
//
// A command that writes a folder (a recording, a run's report, a sweep)
// refuses a folder that already holds something: a second recording into
// the first one would leave the first one's images behind, named by no
// list, and its ground truth overwritten.  With --overwrite, a folder that
// pvbench made is emptied first of what pvbench wrote there: its marker
// file, .pvbench, lists every file the command wrote (note_output), and a
// file no list names (one a user added) refuses the folder.  A folder
// without the marker is never emptied.
#include <string>

namespace pvb {

/// The marker file every prepared output folder holds.
inline constexpr const char* kOutputFolderMarker = ".pvbench";

/// Makes `dir` (and its parents) ready for a command's output: created when
/// missing; when it holds anything, refused (IoError naming `dir`, the
/// option to give and what is there) unless `overwrite`, and then emptied
/// of what pvbench wrote there: the files the lists of the folder and of
/// the folders below it that hold a marker name (with the temporary files
/// of their killed writes), then the folders left empty.  A file no list
/// names refuses the folder, naming it.  The files that are this process's
/// own standard output and error (a sweep's DIR/seed_S/stdout.log) do not
/// count and are kept.  Starts the marker's list anew, naming `command`.
/// The folder is locked (flock) until this process ends: a second process
/// that prepares it meanwhile is refused, so two runs never write one
/// folder.
void prepare_output_folder(const std::string& dir, bool overwrite, const std::string& command);

/// What prepare_output_folder() would refuse, checked without creating or
/// removing anything: for a command that reads its inputs first and must
/// not do its work only to fail at the output (a folder another process
/// holds included).
void check_output_folder(const std::string& dir, bool overwrite);

/// Notes that this process creates or replaces the file `path`: when it
/// lies in an output folder this process prepared (the deepest one), the
/// folder's marker lists it, once, relative to the folder.  Every writer of
/// files calls it (OutputFile, write_file_via_temp, the image writers).
void note_output(const std::string& path);

/// Reserves `path` for the output `role` (--save-map) of this process: the
/// first write of it is that output's, a second one (another output of
/// the command landing on it) throws IoError naming `role` instead of
/// replacing the first.  The IoPlan refuses such paths before any work;
/// this catches what its lists of names miss.
void reserve_output(const std::string& path, const std::string& role);

/// Ends the list of every output folder this process prepared with
/// "failed: WHY": for the apps, when a command stops with an error after
/// it began writing.
void mark_output_folders_failed(const std::string& why);

}  // namespace pvb
