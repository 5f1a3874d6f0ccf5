#pragma once
// Where a recording (`pvbench camera --record FILE`) may be written.
//
// Debian's OpenNI2 2.2 crashes inside Recorder::create when it cannot
// create the file (under a regular file, in a missing folder), and it
// truncates whatever is there.  So the path is checked, and the file created
// by us, before OpenNI2 sees it: a recording is always a new file, never one
// that already exists (docs/openni.md, "Recording").  No OpenNI2 here.
#include <string>
#include <vector>

namespace pvb::openni {

/// A file a run reads or writes besides its recording, named for messages
/// ("the --oni recording", "the --settings file", ...).
struct RunFile {
  std::string path;
  std::string role;
};

/// Throws IoError(record_path, ...) naming the role when the recording would
/// land on one of `files` (empty paths are skipped).
void check_record_not_on(const std::string& record_path, const std::vector<RunFile>& files);

/// The checks of create_new_recording_file without creating anything, for a
/// command to run before it opens a device: an error thrown while OpenNI2
/// has a device open can crash libOpenNI2's teardown (seen with a recording
/// being played back), so every refusal that can come first comes first.
void check_new_recording_path(const std::string& record_path);

/// Creates record_path as a new, empty file (O_CREAT | O_EXCL, so a link is
/// not followed either).  Throws IoError(record_path, ...) with one line when
/// the path is a folder, its folder is missing or not a folder, or a file or
/// link is already there (it is never replaced), or creating it fails.
void create_new_recording_file(const std::string& record_path);

}  // namespace pvb::openni
