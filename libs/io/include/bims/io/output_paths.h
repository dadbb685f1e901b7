// The one rule of every bims program that writes files: a file the program
// creates replaces a symbolic link instead of writing through it, an output
// path that is a FIFO or a device is refused (never replaced by a regular
// file, never written into), and whole-file outputs appear under their
// final name only once complete (written as NAME.PID-TAG.partial, a name of
// the run's own, then renamed). The programs' checks before any
// work (outputs never alias inputs, an earlier run's folder refused unless
// --overwrite) are libs/apps's: bims/apps/output_checks.h.
#pragma once

#include <mutex>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace cv
{
class Mat;
}

namespace bims
{
/** Throws std::runtime_error naming the file when an output file cannot be
 * written where it goes: its folder missing, not a folder, or not writable
 * (access(2)), or the path itself a folder. For programs that write their
 * files at the end of a long run: checked before any work. Empty strings
 * (optional outputs not given) are ignored. */
void checkOutputFilesWritable(const std::vector<std::string>& files);

/** Throws std::runtime_error naming \a path and what it is when it is a
 * FIFO, a character or block device or a socket (not followed through a
 * symbolic link: a link is replaced, not its target): a program's output
 * is a regular file, which would replace it. Every constructor below and
 * checkOutputFilesWritable() check this. */
void refuseSpecialOutput(const std::string& path);

/** "NAME" for a partial file's name "NAME.partial" or "NAME.PID-TAG.partial"
 * (PartialFile's: PID digits, TAG 8 hex digits); "" for another name. */
std::string partialTarget(const std::string& name);

/** Creates a directory and its parents; throws naming it on failure. */
void makeDirs(const std::string& path);

/** Before a program creates the file \a path: a symbolic link there is
 * removed (the link itself, never its target), so the new file replaces the
 * link. Throws naming the path if it is a folder or the link cannot be
 * removed. */
void replaceSymlink(const std::string& path);

/** The per-frame files (a number, then \a ext: 000042.png) directly in
 * \a dir, sorted: the inputs a folder of masks or labels holds. */
std::vector<std::string> frameFilesIn(const std::string& dir,
                                      const std::string& ext = ".png");

/** What a program writes into an output folder, for refusing a folder that
 * holds an earlier run (--overwrite clears only what that run's manifest
 * lists: OutputManifest). */
struct OutputFolderLayout
{
	/** Files by name (e.g. "metrics.json"); PATH.partial files of them
	 * count too. */
	std::vector<std::string> files;
	/** Sub-folders of per-frame files ("" = the folder itself) and the
	 * files' extension: e.g. {"masks", ".png"} holds masks/000042.png. A
	 * per-frame file is named by a number (a scan index or a time stamp:
	 * digits and at most one '.'), then the extension. */
	std::vector<std::pair<std::string, std::string>> frameFolders;
};

/** The files of \a layout found in \a dir (paths inside it, sorted), and
 * its manifest (kOutputManifest) when there is one; none when \a dir does
 * not exist. Anything else in \a dir is not listed. A per-frame sub-folder
 * that is a symbolic link is listed as itself (the link), never followed. */
std::vector<std::string> earlierOutputs(const std::string& dir,
                                        const OutputFolderLayout& layout);

/** A whole-file output written under PATH.PID-TAG.partial (created by the
 * constructor with O_EXCL: a name no other run or object writes, PID the
 * process's id, TAG 8 random hex digits) and renamed to PATH by commit()
 * (std::rename: atomic, and it replaces a symbolic link at PATH, not its
 * target; two runs writing PATH at once each put their own whole file in
 * place, the last one to finish wins). Dropped without commit() (an error
 * on the way), the partial file is removed: PATH is never a half-written
 * file. PATH a FIFO or a device: refused (refuseSpecialOutput). */
class PartialFile
{
 public:
	explicit PartialFile(std::string finalPath);
	~PartialFile();
	PartialFile(const PartialFile&) = delete;
	PartialFile& operator=(const PartialFile&) = delete;

	/** Where to write: PATH.PID-TAG.partial (exists, empty). */
	const std::string& path() const { return partial_; }
	const std::string& finalPath() const { return final_; }
	/** Renames the partial file to PATH; throws naming both on failure. */
	void commit();

 private:
	std::string final_, partial_;
	bool done_ = false;
};

/** Commits \a parts in order (the outputs of one run, e.g. a rawlog and
 * its reference trajectory) holding an exclusive lock (flock(2)) on the
 * folder of the first: of two runs writing the same outputs at once, one
 * run's set is put in place wholly after the other's, never a mix. */
void commitTogether(const std::vector<PartialFile*>& parts);

/** A folder output (a rawlog's OUT_gt/) written as PATH.partial/ (a stale
 * one from a killed run is removed first) and put in place by commit():
 * the new folder gets a manifest (kOutputManifest) of every file in it;
 * an earlier run's files in PATH are removed then, those its manifest
 * lists (a folder of an older bims, without one: the files of \a layout),
 * nothing else (a symbolic link at PATH is replaced, never followed), and
 * the new folder renamed to PATH (its files moved in when PATH holds
 * other files).
 * Dropped without commit(), PATH.partial/ is removed and PATH stays as it
 * was: a failed or killed run never leaves a new ground truth beside an old
 * rawlog. Commit it right after the rawlog's PartialFile. */
class PartialDir
{
 public:
	PartialDir(std::string finalPath, OutputFolderLayout layout);
	~PartialDir();
	PartialDir(const PartialDir&) = delete;
	PartialDir& operator=(const PartialDir&) = delete;

	/** Where to write: PATH.partial. */
	const std::string& path() const { return partial_; }
	const std::string& finalPath() const { return final_; }
	/** Puts the folder in place; throws naming PATH on failure. */
	void commit();

 private:
	std::string final_, partial_;
	OutputFolderLayout layout_;
	bool done_ = false;
};

/** "OUT_gt" for "OUT.rawlog" (also "OUT.rawlog.gz", "OUT.gz": the
 * extensions removed, "_gt" appended): where a rawlog's ground truth is. */
std::string groundTruthDirFor(const std::string& rawlogPath);

/** A file that grows record by record (trajectory.txt, frames.csv, a plain
 * rawlog), for a run that may stop at any time: created (truncated; a
 * symbolic link there replaced), each append() reaches the OS at once and
 * is checked. A failed append (disk full, file size limit) truncates the
 * file back to its last whole record and throws naming the file and the
 * reason: the file never ends in half a record. */
class AppendFile
{
 public:
	explicit AppendFile(std::string path);
	/** Closes (errors dropped: call close() to see them). */
	~AppendFile();
	AppendFile(const AppendFile&) = delete;
	AppendFile& operator=(const AppendFile&) = delete;

	void append(const void* data, size_t n);
	void append(const std::string& s) { append(s.data(), s.size()); }
	/** Closes the file; throws naming it if that fails. */
	void close();
	const std::string& path() const { return path_; }
	/** Bytes written (whole records). */
	size_t size() const { return size_; }

 private:
	std::string path_;
	int fd_ = -1;
	size_t size_ = 0;
};

/** The manifest of an output folder: the files a run wrote into it, one
 * path relative to the folder a line ('#': a comment). --overwrite removes
 * only what it lists (bims/apps/output_checks.h: prepareOutputFolder). */
inline constexpr const char* kOutputManifest = "bims-manifest.txt";

/** A run's manifest, DIR/bims-manifest.txt, created (an earlier one
 * replaced: clear the earlier run's files first) before the run writes
 * anything into DIR. Each file is added before it is created and the line
 * reaches the OS at once, so a killed run's manifest still lists every
 * file it left. Thread-safe. */
class OutputManifest
{
 public:
	/** \a program: named in the manifest's first line. */
	OutputManifest(std::string dir, const std::string& program);
	/** DIR/REL, with REL added to the manifest (once). */
	std::string file(const std::string& rel);
	const std::string& dir() const { return dir_; }

 private:
	std::string dir_;
	std::mutex mutex_;
	std::set<std::string> listed_;
	AppendFile file_;
};

/** The paths the manifest of \a dir lists (relative to it, in order);
 * empty when it has none. Throws naming the manifest and the line when a
 * path is absolute or leaves the folder (`..`): no manifest bims wrote. */
std::vector<std::string> manifestFiles(const std::string& dir);

/** Removes what the manifest of \a dir lists (each file and its partial
 * files of any run (partialTarget);
 * a symbolic link removed, never followed, and a path through a linked
 * folder skipped), then the sub-folders that leaves empty, then the
 * manifest; never anything else. Returns how many files it removed; throws
 * naming a file it cannot remove (\a why: what removes them, in that
 * message). */
size_t removeListedOutputs(const std::string& dir,
                           const std::string& why = "--overwrite");

/** Writes \a bytes to \a path through a PartialFile: every write and the
 * close checked (a full disk is an error naming the file, never a short
 * file), then renamed. */
void writeFileAtomically(const std::string& path, const std::string& bytes);

/** Writes \a bytes into \a part's partial file, every write and the close
 * checked (errors name the final path); commit it afterwards. */
void writePartialFile(PartialFile& part, const std::string& bytes);

/** Encodes \a img in the format of the path's extension (.png) and writes
 * it with writeFileAtomically; throws naming the file. */
void writeImageFile(const std::string& path, const cv::Mat& img);

}  // namespace bims
