#include <bims/io/output_paths.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
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
}  // namespace

void checkOutputFilesWritable(const std::vector<std::string>& files)
{
	for (const auto& f : files)
	{
		if (f.empty()) continue;
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
	if (!fs::is_symlink(st)) return;
	if (!fs::remove(path, ec) || ec)
		throw std::runtime_error(
		    path + ": cannot replace the symbolic link: " + ec.message());
}

PartialFile::PartialFile(std::string finalPath)
    : final_(std::move(finalPath)), partial_(final_ + ".partial")
{
	if (final_.empty()) throw std::invalid_argument("the output path is empty");
	replaceSymlink(partial_);
	std::error_code ec;
	if (fs::is_directory(fs::symlink_status(final_, ec)))
		throw std::runtime_error(final_ + ": is a folder, cannot write a file");
}

PartialFile::~PartialFile()
{
	if (!done_) std::remove(partial_.c_str());
}

void PartialFile::commit()
{
	if (done_) return;
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
	part.commit();
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
		for (const std::string& name : {f, f + ".partial"})
		{
			const fs::path p = fs::path(dir) / name;
			if (fs::is_symlink(p, ec) || fs::exists(p, ec))
				found.push_back(p.string());
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
			    (name.size() > 8 &&
			     name.compare(name.size() - 8, 8, ".partial") == 0 &&
			     isFrameFileName(name.substr(0, name.size() - 8), ext)))
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
	for (const auto& rel : listed)
	{
		if (!reachedWithoutLinks(dir, rel)) continue;  // never followed
		for (const std::string& name : {rel, rel + ".partial"})
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
