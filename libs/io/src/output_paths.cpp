#include <bims/io/output_paths.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <stdexcept>

namespace fs = std::filesystem;

namespace bims
{
namespace
{
std::runtime_error systemError(const std::string& path, const char* what)
{
	return std::runtime_error(path + ": " + what + ": " + std::strerror(errno));
}
void removeLayoutFiles(const std::string& dir,
                       const OutputFolderLayout& layout);
void writeManifestOf(const std::string& dir);

/** What the file at \a path is when it is neither a regular file, a
 * folder, a symbolic link nor absent ("a FIFO (named pipe)"); "" else. */
std::string specialFileKind(const std::string& path)
{
	struct stat st;
	if (::lstat(path.c_str(), &st) != 0) return "";
	const mode_t m = st.st_mode;
	if (S_ISREG(m) || S_ISDIR(m) || S_ISLNK(m)) return "";
	return S_ISFIFO(m)   ? "a FIFO (named pipe)"
	       : S_ISCHR(m)  ? "a character device"
	       : S_ISBLK(m)  ? "a block device"
	       : S_ISSOCK(m) ? "a socket"
	                     : "a special file";
}

/** The process id in a partial file's name "NAME.PID-TAG.partial"; 0 for
 * another name. */
long partialPid(const std::string& name)
{
	const std::string base = partialTarget(name);
	if (base.empty() || base.size() + 8 == name.size()) return 0;
	const std::string tag = name.substr(base.size() + 1);
	return std::strtol(tag.c_str(), nullptr, 10);
}

/** Once per folder and process: removes the partial files in \a dir that
 * a run which no longer exists left (killed: its PID is in the name), so
 * that they do not pile up. Another live run's are never touched. */
void sweepStalePartials(const fs::path& dir)
{
	static std::mutex m;
	static std::set<std::string> swept;
	{
		std::lock_guard<std::mutex> lock(m);
		if (!swept.insert(dir.string()).second) return;
	}
	std::error_code ec;
	for (const auto& e : fs::directory_iterator(dir, ec))
	{
		const long pid = partialPid(e.path().filename().string());
		if (pid <= 0 || pid == ::getpid()) continue;
		if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH)
			continue;  // alive (or not ours to ask): kept
		std::error_code rc;
		if (fs::is_regular_file(fs::symlink_status(e.path(), rc)))
			fs::remove(e.path(), rc);
	}
}

/** A process-unique tag of hexadecimal digits for a partial file's name. */
std::string randomTag()
{
	static std::mutex m;
	static std::mt19937_64 gen(std::random_device{}());
	std::lock_guard<std::mutex> lock(m);
	char b[24];
	std::snprintf(b, sizeof(b), "%08llx",
	              static_cast<unsigned long long>(gen() & 0xffffffffu));
	return b;
}
}  // namespace

void refuseSpecialOutput(const std::string& path)
{
	const std::string kind = specialFileKind(path);
	if (!kind.empty())
		throw std::runtime_error(
		    path + ": is " + kind +
		    ", not a regular file: bims writes its outputs as regular files "
		    "(written whole and renamed into place), which would replace "
		    "it; refused: give the path of a file");
}

std::string partialTarget(const std::string& name)
{
	static const std::string ext = ".partial";
	if (name.size() <= ext.size() ||
	    name.compare(name.size() - ext.size(), ext.size(), ext) != 0)
		return "";
	std::string base = name.substr(0, name.size() - ext.size());
	// a run's tag: ".<pid>-<8 hex digits>"
	const size_t dot = base.rfind('.');
	if (dot == std::string::npos || dot == 0) return base;
	const std::string tag = base.substr(dot + 1);
	const size_t dash = tag.find('-');
	if (dash == std::string::npos || dash == 0 || tag.size() - dash - 1 != 8)
		return base;
	for (size_t i = 0; i < tag.size(); i++)
		if (i != dash && !(i < dash ? std::isdigit(uint8_t(tag[i]))
		                            : std::isxdigit(uint8_t(tag[i]))))
			return base;
	return base.substr(0, dot);
}

void checkOutputFilesWritable(const std::vector<std::string>& files)
{
	for (const auto& f : files)
	{
		if (f.empty()) continue;
		refuseSpecialOutput(f);
		std::error_code ec;
		if (fs::is_directory(f, ec))
			throw std::runtime_error(f +
			                         ": is a folder; a file is written "
			                         "there");
		fs::path dir = fs::path(f).parent_path();
		if (dir.empty()) dir = ".";
		if (!fs::exists(dir, ec))
			throw std::runtime_error("cannot write " + f + ": its folder " +
			                         dir.string() + " does not exist");
		if (!fs::is_directory(dir, ec))
			throw std::runtime_error("cannot write " + f + ": " + dir.string() +
			                         " is not a folder");
		if (access(dir.c_str(), W_OK | X_OK) != 0)
			throw std::runtime_error("cannot write " + f + ": its folder " +
			                         dir.string() + " is not writable (" +
			                         std::strerror(errno) + ")");
	}
}

void makeDirs(const std::string& path)
{
	std::error_code ec;
	std::filesystem::create_directories(path, ec);
	if (ec)
		throw std::runtime_error(path +
		                         ": cannot create directory: " + ec.message());
}

void replaceSymlink(const std::string& path)
{
	std::error_code ec;
	const auto st = fs::symlink_status(path, ec);
	if (fs::is_directory(st))
		throw std::runtime_error(path + ": is a folder, cannot write a file");
	refuseSpecialOutput(path);
	if (!fs::is_symlink(st)) return;
	if (!fs::remove(path, ec) || ec)
		throw std::runtime_error(
		    path + ": cannot replace the symbolic link: " + ec.message());
}

PartialFile::PartialFile(std::string finalPath) : final_(std::move(finalPath))
{
	if (final_.empty()) throw std::invalid_argument("the output path is empty");
	std::error_code ec;
	if (fs::is_directory(fs::symlink_status(final_, ec)))
		throw std::runtime_error(final_ + ": is a folder, cannot write a file");
	refuseSpecialOutput(final_);
	// a killed run's partial files: the old fixed name, and those of
	// processes that no longer exist
	fs::path dir = fs::path(final_).parent_path();
	if (dir.empty()) dir = ".";
	if (fs::is_regular_file(fs::symlink_status(final_ + ".partial", ec)) ||
	    fs::is_symlink(fs::symlink_status(final_ + ".partial", ec)))
		fs::remove(final_ + ".partial", ec);
	sweepStalePartials(dir);
	// a name of this run's own, created here (O_EXCL): two runs writing
	// the same output at once never write into one file
	const std::string stem = final_ + "." + std::to_string(::getpid()) + "-";
	for (int attempt = 0;; attempt++)
	{
		partial_ = stem + randomTag() + ".partial";
		const int fd = ::open(partial_.c_str(),
		                      O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
		if (fd >= 0)
		{
			::close(fd);
			break;
		}
		if (errno != EEXIST || attempt == 100)
			throw systemError(partial_, "cannot create");
	}
}

PartialFile::~PartialFile()
{
	if (!done_) std::remove(partial_.c_str());
}

void commitTogether(const std::vector<PartialFile*>& parts)
{
	if (parts.empty()) return;
	fs::path dir = fs::path(parts.front()->finalPath()).parent_path();
	if (dir.empty()) dir = ".";
	// an exclusive lock on the folder while the files are renamed: another
	// run's set goes in wholly before or after this one's
	const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
	if (fd >= 0)
		while (::flock(fd, LOCK_EX) != 0 && errno == EINTR)
		{
		}
	try
	{
		for (PartialFile* p : parts) p->commit();
	}
	catch (...)
	{
		if (fd >= 0) ::close(fd);
		throw;
	}
	if (fd >= 0) ::close(fd);  // (releases the lock)
}

void PartialFile::commit()
{
	if (done_) return;
	refuseSpecialOutput(final_);  // (made there since the start?)
	if (std::rename(partial_.c_str(), final_.c_str()) != 0)
		throw std::runtime_error(final_ + ": cannot rename " + partial_ +
		                         " to it: " + std::strerror(errno));
	done_ = true;
}

PartialDir::PartialDir(std::string finalPath, OutputFolderLayout layout)
    : final_(std::move(finalPath)),
      partial_(final_ + ".partial"),
      layout_(std::move(layout))
{
	std::error_code ec;
	fs::remove_all(partial_, ec);  // a killed run's: bims's by its name
	if (ec)
		throw std::runtime_error(partial_ +
		                         ": cannot remove the folder a stopped run "
		                         "left: " +
		                         ec.message());
	makeDirs(partial_);
}

PartialDir::~PartialDir()
{
	if (done_) return;
	std::error_code ec;
	fs::remove_all(partial_, ec);
}

void PartialDir::commit()
{
	if (done_) return;
	const auto fail = [&](const std::string& what, const std::error_code& ec)
	{
		return std::runtime_error(final_ + ": " + what + ": " + ec.message() +
		                          " (the new files stay in " + partial_ + ")");
	};
	std::error_code ec;
	writeManifestOf(partial_);
	const auto st = fs::symlink_status(final_, ec);
	if (fs::is_symlink(st))
	{
		if (!fs::remove(final_, ec) || ec)
			throw fail("cannot replace the symbolic link", ec);
	}
	else if (fs::exists(st))
	{
		if (!fs::is_directory(st))
			throw std::runtime_error(final_ +
			                         ": exists and is not a folder (the new "
			                         "files stay in " +
			                         partial_ + ")");
		// the earlier run's: what its manifest lists, or (a folder an
		// older bims wrote, without one) the files of the layout
		if (fs::exists(fs::path(final_) / kOutputManifest, ec))
			removeListedOutputs(final_, "the new " + final_);
		else
			removeLayoutFiles(final_, layout_);
		if (fs::is_empty(final_, ec)) fs::remove(final_, ec);
	}
	if (!fs::exists(fs::symlink_status(final_, ec)))
	{
		fs::rename(partial_, final_, ec);
		if (ec) throw fail("cannot rename " + partial_ + " to it", ec);
		done_ = true;
		return;
	}
	// PATH holds other files than an earlier run's: move ours in
	std::vector<fs::path> files;
	for (const auto& e : fs::recursive_directory_iterator(partial_))
		if (!e.is_directory()) files.push_back(e.path());
	for (const auto& f : files)
	{
		const fs::path to = fs::path(final_) / fs::relative(f, partial_);
		fs::create_directories(to.parent_path(), ec);
		if (!ec) fs::rename(f, to, ec);
		if (ec) throw fail("cannot move " + f.string() + " into it", ec);
	}
	fs::remove_all(partial_, ec);
	done_ = true;
}

std::string groundTruthDirFor(const std::string& rawlogPath)
{
	fs::path p(rawlogPath);
	if (p.extension() == ".rawlog" || p.extension() == ".gz")
	{
		p.replace_extension();
		if (p.extension() == ".rawlog") p.replace_extension();
	}
	return p.string() + "_gt";
}

void writeFileAtomically(const std::string& path, const std::string& bytes)
{
	PartialFile part(path);
	writePartialFile(part, bytes);
	part.commit();
}

void writePartialFile(PartialFile& part, const std::string& bytes)
{
	const std::string& path = part.finalPath();
	const int fd = ::open(part.path().c_str(),
	                      O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
	if (fd < 0) throw systemError(path, "cannot create");
	size_t done = 0;
	while (done < bytes.size())
	{
		const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
		if (n < 0 && errno == EINTR) continue;
		if (n <= 0)
		{
			const auto e = systemError(path, "write failed");
			::close(fd);
			throw e;
		}
		done += static_cast<size_t>(n);
	}
	if (::close(fd) != 0) throw systemError(path, "write failed on close");
}

AppendFile::AppendFile(std::string path) : path_(std::move(path))
{
	replaceSymlink(path_);
	fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
	if (fd_ < 0) throw systemError(path_, "cannot create");
}

AppendFile::~AppendFile()
{
	if (fd_ >= 0) ::close(fd_);
}

void AppendFile::append(const void* data, size_t n)
{
	if (fd_ < 0) throw std::runtime_error(path_ + ": write after close");
	const char* p = static_cast<const char*>(data);
	size_t done = 0;
	while (done < n)
	{
		const ssize_t k = ::write(fd_, p + done, n - done);
		if (k < 0 && errno == EINTR) continue;
		if (k <= 0)
		{
			const auto e = systemError(path_, "write failed");
			// back to the last whole record (shrinking is always allowed)
			if (::ftruncate(fd_, static_cast<off_t>(size_)) == 0)
				::lseek(fd_, static_cast<off_t>(size_), SEEK_SET);
			throw e;
		}
		done += static_cast<size_t>(k);
	}
	size_ += n;
}

void AppendFile::close()
{
	if (fd_ < 0) return;
	const int fd = fd_;
	fd_ = -1;
	if (::close(fd) != 0) throw systemError(path_, "write failed on close");
}

void writeImageFile(const std::string& path, const cv::Mat& img)
{
	std::vector<uchar> bytes;
	bool ok = false;
	try
	{
		ok = cv::imencode(fs::path(path).extension().string(), img, bytes);
	}
	catch (const cv::Exception& e)
	{
		throw std::runtime_error(path + ": cannot encode image: " + e.what());
	}
	if (!ok) throw std::runtime_error(path + ": cannot encode image");
	writeFileAtomically(path, std::string(bytes.begin(), bytes.end()));
}

}  // namespace bims

namespace bims
{
namespace
{
/** "000042.png", "1548339824.89375.png" with ext ".png". */
bool isFrameFileName(const std::string& name, const std::string& ext)
{
	if (name.size() <= ext.size() ||
	    name.compare(name.size() - ext.size(), ext.size(), ext) != 0)
		return false;
	const std::string stem = name.substr(0, name.size() - ext.size());
	size_t dots = 0;
	for (char c : stem)
		if (c == '.')
			++dots;
		else if (c < '0' || c > '9')
			return false;
	return dots <= 1 && stem.front() != '.' && stem.back() != '.';
}
}  // namespace

std::vector<std::string> earlierOutputs(const std::string& dir,
                                        const OutputFolderLayout& layout)
{
	namespace fs = std::filesystem;
	std::vector<std::string> found;
	std::error_code ec;
	if (!fs::is_directory(dir, ec)) return found;
	if (const fs::path m = fs::path(dir) / kOutputManifest;
	    fs::is_symlink(m, ec) || fs::exists(m, ec))
		found.push_back(m.string());
	for (const auto& f : layout.files)
	{
		const fs::path p = fs::path(dir) / f;
		if (fs::is_symlink(p, ec) || fs::exists(p, ec))
			found.push_back(p.string());
	}
	// their partial files, of any run (NAME.partial, NAME.TAG.partial)
	if (!layout.files.empty())
	{
		const std::set<std::string> names(layout.files.begin(),
		                                  layout.files.end());
		for (const auto& e : fs::directory_iterator(dir, ec))
		{
			const std::string base =
			    partialTarget(e.path().filename().string());
			if (!base.empty() && names.count(base))
				found.push_back(e.path().string());
		}
	}
	for (const auto& [sub, ext] : layout.frameFolders)
	{
		const fs::path d = sub.empty() ? fs::path(dir) : fs::path(dir) / sub;
		if (!sub.empty() && fs::is_symlink(d, ec))
		{
			// the link itself, never what it points to
			found.push_back(d.string());
			continue;
		}
		if (!fs::is_directory(d, ec)) continue;
		for (const auto& e : fs::directory_iterator(d, ec))
		{
			const std::string name = e.path().filename().string();
			if (isFrameFileName(name, ext) ||
			    isFrameFileName(partialTarget(name), ext))
				found.push_back(e.path().string());
		}
	}
	std::sort(found.begin(), found.end());
	return found;
}

namespace
{
/** PartialDir's: the files of \a layout in \a dir (a folder bims names
 * after its rawlog) and the per-frame sub-folders left empty. */
void removeLayoutFiles(const std::string& dir, const OutputFolderLayout& layout)
{
	for (const auto& f : earlierOutputs(dir, layout))
	{
		std::error_code ec;
		if (fs::is_directory(fs::symlink_status(f, ec)))
			throw std::runtime_error(f +
			                         ": is a folder where the run writes a "
			                         "file; not removed");
		if (!fs::remove(f, ec) || ec)
			throw std::runtime_error(f + ": cannot remove it: " + ec.message());
	}
	for (const auto& [sub, ext] : layout.frameFolders)
	{
		std::error_code ec;
		if (!sub.empty() && fs::is_empty(fs::path(dir) / sub, ec))
			fs::remove(fs::path(dir) / sub, ec);
	}
}

/** PartialDir's: the manifest of \a dir listing every file in it (sorted),
 * so that the next run replaces exactly these. */
void writeManifestOf(const std::string& dir)
{
	std::vector<std::string> files;
	for (const auto& e : fs::recursive_directory_iterator(dir))
		if (!e.is_directory())
			files.push_back(e.path().lexically_relative(dir).string());
	std::sort(files.begin(), files.end());
	OutputManifest m(dir, "bims (the ground truth beside a rawlog)");
	for (const auto& f : files) m.file(f);
}

/** \a rel's folders below \a dir are real folders (no link on the way). */
bool reachedWithoutLinks(const fs::path& dir, const fs::path& rel)
{
	fs::path p = dir;
	std::error_code ec;
	for (auto it = rel.begin(); std::next(it) != rel.end(); ++it)
	{
		p /= *it;
		if (!fs::is_directory(fs::symlink_status(p, ec))) return false;
	}
	return true;
}
}  // namespace

OutputManifest::OutputManifest(std::string dir, const std::string& program)
    : dir_(std::move(dir)), file_(dir_ + "/" + kOutputManifest)
{
	file_.append("# " + program +
	             ": the files it wrote into this folder, one a line; "
	             "--overwrite removes only these\n");
}

std::string OutputManifest::file(const std::string& rel)
{
	{
		std::lock_guard<std::mutex> lock(mutex_);
		if (listed_.insert(rel).second) file_.append(rel + "\n");
	}
	return dir_ + "/" + rel;
}

std::vector<std::string> manifestFiles(const std::string& dir)
{
	const std::string path = dir + "/" + kOutputManifest;
	std::vector<std::string> files;
	std::ifstream in(path);
	if (!in) return files;
	std::string line;
	for (size_t n = 1; std::getline(in, line); ++n)
	{
		if (line.empty() || line[0] == '#') continue;
		const fs::path rel(line);
		bool leaves = rel.is_absolute();
		for (const auto& part : rel) leaves = leaves || part == "..";
		if (leaves)
			throw std::runtime_error(
			    path + ":" + std::to_string(n) + ": " + line +
			    " is outside the folder: not a manifest bims wrote (remove "
			    "the earlier outputs yourself)");
		files.push_back(line);
	}
	return files;
}

size_t removeListedOutputs(const std::string& dir, const std::string& why)
{
	const auto listed = manifestFiles(dir);
	size_t removed = 0;
	std::set<fs::path> folders;
	// the partial files of each folder, of any run: NAME -> its partials
	std::map<fs::path, std::map<std::string, std::vector<std::string>>>
	    partials;
	const auto partialsOf = [&](const fs::path& rel)
	{
		const fs::path sub = rel.parent_path();
		auto [it, fresh] = partials.try_emplace(sub);
		if (fresh)
		{
			std::error_code ec;
			for (const auto& e :
			     fs::directory_iterator(fs::path(dir) / sub, ec))
			{
				const std::string name = e.path().filename().string();
				const std::string base = partialTarget(name);
				if (!base.empty())
					it->second[base].push_back((sub / name).string());
			}
		}
		const auto p = it->second.find(rel.filename().string());
		return p == it->second.end() ? std::vector<std::string>{} : p->second;
	};
	for (const auto& rel : listed)
	{
		if (!reachedWithoutLinks(dir, rel)) continue;  // never followed
		std::vector<std::string> names = partialsOf(rel);
		names.insert(names.begin(), rel);
		for (const std::string& name : names)
		{
			const fs::path p = fs::path(dir) / name;
			std::error_code ec;
			const auto st = fs::symlink_status(p, ec);
			if (!fs::exists(st) && !fs::is_symlink(st)) continue;
			if (fs::is_directory(st))
				throw std::runtime_error(p.string() +
				                         ": is a folder where the run wrote a "
				                         "file; not removed");
			if (!fs::remove(p, ec) || ec)
				throw std::runtime_error(p.string() +
				                         ": cannot remove it for " + why +
				                         ": " + ec.message());
			++removed;
		}
		for (fs::path f = fs::path(rel).parent_path(); !f.empty();
		     f = f.parent_path())
			folders.insert(f);
	}
	// the deepest first
	for (auto it = folders.rbegin(); it != folders.rend(); ++it)
	{
		const fs::path p = fs::path(dir) / *it;
		std::error_code ec;
		if (fs::is_directory(fs::symlink_status(p, ec)) && fs::is_empty(p, ec))
			fs::remove(p, ec);
	}
	std::error_code ec;
	fs::remove(fs::path(dir) / kOutputManifest, ec);
	return removed;
}

std::vector<std::string> frameFilesIn(const std::string& dir,
                                      const std::string& ext)
{
	std::vector<std::string> files;
	std::error_code ec;
	for (const auto& e : fs::directory_iterator(dir, ec))
		if (isFrameFileName(e.path().filename().string(), ext))
			files.push_back(e.path().string());
	std::sort(files.begin(), files.end());
	return files;
}

}  // namespace bims
