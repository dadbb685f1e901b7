// Reading a Stray Scanner capture's files: odometry.csv, imu.csv,
// camera_matrix.csv and the depth/ listing (stray_import.h).
#include <bims/common/input_file.h>
#include <bims/eval/stray_import.h>
#include <mrpt/core/format.h>
#include <mrpt/poses/CPose3DQuat.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>

namespace bims::eval
{
namespace fs = std::filesystem;

namespace
{
std::string trim(const std::string& s)
{
	const auto a = s.find_first_not_of(" \t\r\n");
	if (a == std::string::npos) return {};
	const auto b = s.find_last_not_of(" \t\r\n");
	return s.substr(a, b - a + 1);
}

/** The comma-separated fields of \a line, each trimmed. */
std::vector<std::string> fields(const std::string& line)
{
	std::vector<std::string> out;
	std::string cell;
	std::istringstream ss(line);
	while (std::getline(ss, cell, ',')) out.push_back(trim(cell));
	if (!line.empty() && line.back() == ',') out.push_back("");
	return out;
}

std::string joined(const std::vector<std::string>& names)
{
	std::string s;
	for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
	return s;
}

/** \a s with bytes outside printable ASCII shown as \xNN (a byte-order
 * mark in the middle, a binary byte), cut to 120 characters. */
std::string printable(const std::string& s)
{
	std::string out;
	for (const char ch : s)
	{
		const auto c = static_cast<unsigned char>(ch);
		if (c >= 0x20 && c < 0x7f)
			out += ch;
		else
		{
			char b[8];
			std::snprintf(b, sizeof(b), "\\x%02X", c);
			out += b;
		}
		if (out.size() > 120) return out + "...";
	}
	return out;
}

std::runtime_error rowError(const std::string& path, size_t line,
                            const std::string& what)
{
	return std::runtime_error(path + ":" + std::to_string(line) + ": " + what);
}

/** A CSV of a header line \a names and rows of as many finite numbers, time
 * (the first column) strictly increasing, read one row at a time (nothing
 * of a row is kept but what \a row takes): \a row(line, values, cells). */
using CsvRowFn = std::function<void(size_t, const std::vector<double>&,
                                    const std::vector<std::string>&)>;

void readNumericCsv(const std::string& path,
                    const std::vector<std::string>& names, const CsvRowFn& row)
{
	LineReader f(path, "CSV file");
	std::string line;
	// the header: the columns' names in this order (the meaning and the
	// sign of every column below depend on it)
	bool any = false;
	while (f.next(line))
		if (!trim(line).empty())
		{
			any = true;
			break;
		}
	if (!any) throw std::runtime_error(path + ": empty (no header, no rows)");
	if (fields(line) != names)
		throw rowError(path, f.lineNumber(),
		               "expected the header '" + joined(names) + "', got '" +
		                   printable(trim(line)) + "'");
	size_t rows = 0;
	double previous = 0;
	std::vector<double> v(names.size());
	while (f.next(line))
	{
		const size_t n = f.lineNumber();
		if (trim(line).empty()) continue;
		const std::vector<std::string> text = fields(line);
		if (text.size() != names.size())
			throw rowError(path, n,
			               "expected " + std::to_string(names.size()) +
			                   " comma-separated values (" + joined(names) +
			                   "), got " + std::to_string(text.size()) +
			                   " (a truncated row?)");
		for (size_t i = 0; i < names.size(); i++)
		{
			const std::string& s = text[i];
			char* end = nullptr;
			errno = 0;
			const double x = std::strtod(s.c_str(), &end);
			if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE ||
			    !std::isfinite(x))
				throw rowError(path, n,
				               names[i] + " '" + printable(s) +
				                   "' is not a finite number");
			v[i] = x;
		}
		// the rawlog's clock holds no time before 1970 (a negative stamp
		// would wrap) and bims refuses absurd ones
		if (!(v[0] >= 0 && v[0] <= kMaxStraySeconds))
		{
			char b[200];
			std::snprintf(b, sizeof(b),
			              "timestamp %.9g is not a time bims takes: seconds "
			              "from 0 to %.0f (ROS's range, to the year 2106) "
			              "are accepted",
			              v[0], kMaxStraySeconds);
			throw rowError(path, n, b);
		}
		if (rows > 0 && !(v[0] > previous))
		{
			char b[160];
			std::snprintf(b, sizeof(b),
			              "timestamp %.9f is not after the previous row's "
			              "%.9f (time must increase)",
			              v[0], previous);
			throw rowError(path, n, b);
		}
		previous = v[0];
		rows++;
		row(n, v, text);
	}
	if (rows == 0) throw std::runtime_error(path + ": no rows");
}

/** Whether nothing is at \a path: no file and no symbolic link (a link
 * to nothing or a link loop is there, and its reader names it). */
bool absent(const std::string& path)
{
	std::error_code ec;
	return !fs::exists(fs::symlink_status(path, ec));
}

/** "000123" -> 123; -1 when not all digits. */
long frameNumber(const std::string& s)
{
	if (s.empty() || s.size() > 9) return -1;
	for (char c : s)
		if (c < '0' || c > '9') return -1;
	return std::stol(s);
}
}  // namespace

mrpt::poses::CPose3D StrayFrame::pose() const
{
	const double n =
	    std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
	const mrpt::math::CQuaternionDouble qq(q[3] / n, q[0] / n, q[1] / n,
	                                       q[2] / n);
	return mrpt::poses::CPose3D(mrpt::poses::CPose3DQuat(p[0], p[1], p[2], qq));
}

std::vector<StrayFrame> readStrayOdometry(const std::string& path)
{
	std::vector<StrayFrame> out;
	std::map<long, size_t> lineOf;
	readNumericCsv(
	    path, {"timestamp", "frame", "x", "y", "z", "qx", "qy", "qz", "qw"},
	    [&](size_t line, const std::vector<double>& v,
	        const std::vector<std::string>& text)
	    {
		    StrayFrame f;
		    f.t = v[0];
		    f.line = line;
		    f.index = frameNumber(text[1]);
		    if (f.index < 0)
			    throw rowError(path, line,
			                   "frame '" + printable(text[1]) +
			                       "' is not a frame number (digits)");
		    if (const auto it = lineOf.find(f.index); it != lineOf.end())
			    throw rowError(path, line,
			                   "frame " + text[1] + " is given twice (line " +
			                       std::to_string(it->second) + ")");
		    lineOf[f.index] = line;
		    for (int i = 0; i < 3; i++) f.p[i] = v[2 + i];
		    for (int i = 0; i < 4; i++) f.q[i] = v[5 + i];
		    const double qn = std::sqrt(f.q[0] * f.q[0] + f.q[1] * f.q[1] +
		                                f.q[2] * f.q[2] + f.q[3] * f.q[3]);
		    if (std::abs(qn - 1.0) > 1e-3)
			    throw rowError(path, line,
			                   "quaternion qx qy qz qw is not unit (norm " +
			                       std::to_string(qn) + ")");
		    out.push_back(f);
	    });
	return out;
}

std::vector<StrayImuSample> readStrayImu(const std::string& path)
{
	std::vector<StrayImuSample> out;
	readNumericCsv(
	    path,
	    {"timestamp", "a_x", "a_y", "a_z", "alpha_x", "alpha_y", "alpha_z"},
	    [&](size_t, const std::vector<double>& v,
	        const std::vector<std::string>&)
	    {
		    StrayImuSample s;
		    s.t = v[0];
		    for (int i = 0; i < 3; i++)
		    {
			    s.a[i] = v[1 + i];
			    s.alpha[i] = v[4 + i];
		    }
		    out.push_back(s);
	    });
	return out;
}

void readStrayCameraMatrix(const std::string& path, double K[3][3])
{
	if (inputFileProblem(path) == "no such file")
		throw std::runtime_error(path + ": cannot open: no such file");
	LineReader f(path, "camera matrix");
	std::string line;
	size_t n = 0, row = 0;
	while (f.next(line))
	{
		n = f.lineNumber();
		if (trim(line).empty()) continue;
		if (row == 3)
			throw rowError(path, n, "a 4th row: expected a 3x3 matrix");
		const auto cells = fields(line);
		if (cells.size() != 3)
			throw rowError(path, n,
			               "expected 3 comma-separated numbers, got " +
			                   std::to_string(cells.size()));
		for (int i = 0; i < 3; i++)
		{
			char* end = nullptr;
			const double x = std::strtod(cells[i].c_str(), &end);
			if (cells[i].empty() || end != cells[i].c_str() + cells[i].size() ||
			    !std::isfinite(x))
				throw rowError(
				    path, n,
				    "'" + printable(cells[i]) + "' is not a finite number");
			K[row][i] = x;
		}
		const bool ok = row == 0 ? K[0][0] > 0 && K[0][1] == 0
		                : row == 1
		                    ? K[1][0] == 0 && K[1][1] > 0
		                    : K[2][0] == 0 && K[2][1] == 0 && K[2][2] == 1;
		if (!ok)
			throw rowError(path, n,
			               row == 0
			                   ? "expected 'fx, 0, cx' with fx > 0 (no skew)"
			               : row == 1 ? "expected '0, fy, cy' with fy > 0"
			                          : "expected '0, 0, 1'");
		row++;
	}
	if (row != 3)
		throw std::runtime_error(path + ": " + std::to_string(row) +
		                         " rows, expected 3 (a 3x3 camera matrix)");
}

namespace
{
/** depth/NNNNNN.png by frame number (any other .png: an error). */
std::map<long, std::string> strayDepthImages(const fs::path& depthDir)
{
	if (!fs::is_directory(depthDir))
		throw std::runtime_error(depthDir.string() +
		                         ": not a directory (the depth images)");
	std::map<long, std::string> depthOf;
	for (const auto& e : fs::directory_iterator(depthDir))
	{
		if (e.path().extension() != ".png") continue;
		const long k = frameNumber(e.path().stem().string());
		if (k < 0)
			throw std::runtime_error(
			    e.path().string() +
			    ": not named as a frame (NNNNNN.png, the frame column of "
			    "odometry.csv)");
		depthOf[k] = e.path().string();
	}
	return depthOf;
}

/** Whether the capture has confidence images (confidence/ that is no
 * folder: an error). */
bool hasConfidenceFolder(const std::string& confDir)
{
	if (absent(confDir)) return false;
	std::error_code ec;
	if (!fs::is_directory(confDir, ec))
	{
		const std::string why = inputFileProblem(confDir);
		throw std::runtime_error(confDir +
		                         ": not a folder of ARKit confidence images (" +
		                         (why.empty() ? std::string("a file") : why) +
		                         "): remove it to import without confidence");
	}
	return true;
}

/** Each frame of \a c its depth image (and confidence image): exactly the
 * frames of odometry.csv have one (else an error naming both). */
void matchDepthImages(StrayCapture& c, std::map<long, std::string> depthOf,
                      const fs::path& dir, const std::string& odometry)
{
	for (auto& f : c.frames)
	{
		const auto it = depthOf.find(f.index);
		if (it == depthOf.end())
		{
			throw std::runtime_error(
			    odometry + ":" + std::to_string(f.line) + ": frame " +
			    std::to_string(f.index) + " has no depth image (" +
			    (dir / "depth" / mrpt::format("%06ld.png", f.index)).string() +
			    ")");
		}
		f.depthPath = it->second;
		if (c.hasConfidence)
			f.confidencePath =
			    (dir / "confidence" / fs::path(it->second).filename()).string();
		depthOf.erase(it);
	}
	if (!depthOf.empty())
		throw std::runtime_error(depthOf.begin()->second + ": frame " +
		                         std::to_string(depthOf.begin()->first) +
		                         " has no row in " + odometry);
}

/** imu.csv, confidence/ and rgb.mp4 when present; said to \a warn when
 * not. */
void readStrayExtras(StrayCapture& c, const fs::path& dir,
                     const WarningCallback& warn)
{
	const std::string imu = (dir / "imu.csv").string();
	c.hasImu = !absent(imu);
	if (c.hasImu)
		c.imu = readStrayImu(imu);
	else
		reportWarning(warn, {Warning::Kind::Warning, imu,
		                     "not found: depth only, no IMU observations"});
	if (!c.hasConfidence)
		reportWarning(warn,
		              {Warning::Kind::Warning, (dir / "confidence").string(),
		               "not found: every depth reading kept (no ARKit "
		               "confidence to filter by)"});
	if (!absent((dir / "rgb.mp4").string()))
	{
		c.videoPath = (dir / "rgb.mp4").string();
		checkInputFile(c.videoPath, "video");  // (a FIFO would block)
	}
	else
		reportWarning(warn, {Warning::Kind::Note, (dir / "rgb.mp4").string(),
		                     "not found: depth and IMU only, the scans have "
		                     "no colour image"});
}
}  // namespace

StrayCapture readStrayCapture(const std::string& folder,
                              const WarningCallback& warn)
{
	const fs::path dir(folder);
	if (!fs::is_directory(dir))
		throw std::runtime_error(folder + ": not a directory");
	StrayCapture c;
	c.path = folder;
	const std::string odometry = (dir / "odometry.csv").string();
	if (absent(odometry))
		throw std::runtime_error(odometry +
		                         ": not found (the frames' poses and clock; "
		                         "is this a Stray Scanner capture?)");
	c.frames = readStrayOdometry(odometry);
	// depth/NNNNNN.png: exactly the frames of odometry.csv
	std::map<long, std::string> depthOf = strayDepthImages(dir / "depth");
	c.hasConfidence = hasConfidenceFolder((dir / "confidence").string());
	matchDepthImages(c, std::move(depthOf), dir, odometry);
	readStrayCameraMatrix((dir / "camera_matrix.csv").string(), c.K);
	readStrayExtras(c, dir, warn);
	return c;
}

mrpt::img::TCamera strayDepthCamera(const double K[3][3], int colourWidth,
                                    int colourHeight, int width, int height)
{
	const double sx = static_cast<double>(width) / colourWidth,
	             sy = static_cast<double>(height) / colourHeight;
	mrpt::img::TCamera c;
	c.ncols = static_cast<uint32_t>(width);
	c.nrows = static_cast<uint32_t>(height);
	c.setIntrinsicParamsFromValues(K[0][0] * sx, K[1][1] * sy, K[0][2] * sx,
	                               K[1][2] * sy);
	c.distortion = mrpt::img::DistortionModel::none;
	return c;
}

}  // namespace bims::eval
