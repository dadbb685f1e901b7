#include <bims/common/rawlog.h>
#include <mrpt/img/CImage.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/archiveFrom_std_streams.h>
#include <mrpt/system/filesystem.h>

namespace bims
{
std::string rawlogImagesDirectory(const std::string& rawlogPath)
{
	std::string dir = mrpt::system::extractFileDirectory(rawlogPath);
	if (!dir.empty() && dir.back() != '/') dir += '/';
	return dir + mrpt::system::extractFileName(rawlogPath) + "_Images";
}

RawlogReader::RawlogReader(const std::string& path) : path_(path)
{
	if (!mrpt::system::fileExists(path))
		throw RawlogError(path + ": no such rawlog file");
	if (!in_.open(path)) throw RawlogError(path + ": cannot open rawlog file");
	arch_ = std::make_unique<
	    mrpt::serialization::CArchiveStreamBase<mrpt::io::CFileGZInputStream>>(
	    in_);
	const std::string imgDir = rawlogImagesDirectory(path);
	if (mrpt::system::directoryExists(imgDir))
		mrpt::img::CImage::setImagesPathBase(imgDir);
}

mrpt::obs::CObservation::Ptr RawlogReader::next()
{
	while (pending_.empty())
	{
		if (atEnd_) return nullptr;
		mrpt::serialization::CSerializable::Ptr obj;
		const uint64_t pos0 = in_.getPosition();
		try
		{
			obj = arch_->ReadObject();
			++entry_;
		}
		catch (const std::exception& e)
		{
			// EOF before the first byte of an object is the clean end.
			if (in_.getPosition() == pos0 && in_.checkEOF())
			{
				atEnd_ = true;
				return nullptr;
			}
			++entry_;
			std::string what = e.what();
			if (what.size() > 300) what = what.substr(0, 300) + "...";
			throw RawlogError(
			    path_ + ": truncated or corrupt rawlog at entry " +
			    std::to_string(entry_) + " (" + std::to_string(nObs_) +
			    " observations read before): " + what);
		}
		if (!obj)
			throw RawlogError(path_ + ": null object at entry " +
			                  std::to_string(entry_));
		if (auto o = std::dynamic_pointer_cast<mrpt::obs::CObservation>(obj))
			pending_.push_back(o);
		else if (auto sf =
		             std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(obj))
			for (const auto& so : *sf) pending_.push_back(so);
		else if (std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(obj))
			continue;  // odometry actions are not used by bims
		else
			throw RawlogError(
			    path_ + ": entry " + std::to_string(entry_) + " is a " +
			    obj->GetRuntimeClass()->className +
			    ", not an observation, sensory frame or action collection");
	}
	auto o = pending_.front();
	pending_.pop_front();
	++nObs_;
	return o;
}

RawlogWriter::RawlogWriter(const std::string& path, int gzLevel) : path_(path)
{
	if (gzLevel < 0 || gzLevel > 9)
		throw RawlogError(path + ": gzip level must be in 0..9");
	if (gzLevel == 0)
	{
		plain_.open(path, std::ios::binary | std::ios::trunc);
		if (!plain_) throw RawlogError(path + ": cannot create rawlog file");
		arch_ = std::make_unique<
		    mrpt::serialization::CArchiveStreamBase<std::ostream>>(plain_);
	}
	else
	{
		if (!gz_.open(path, gzLevel, std::nullopt,
		              mrpt::io::OpenMode::TRUNCATE))
			throw RawlogError(path + ": cannot create rawlog file");
		arch_ = std::make_unique<mrpt::serialization::CArchiveStreamBase<
		    mrpt::io::CFileGZOutputStream>>(gz_);
	}
	open_ = true;
}

RawlogWriter::~RawlogWriter()
{
	try
	{
		close();
	}
	catch (...)
	{
	}
}

void RawlogWriter::write(const mrpt::obs::CObservation& obs)
{
	if (!open_) throw RawlogError(path_ + ": write after close");
	try
	{
		*arch_ << obs;
	}
	catch (const std::exception& e)
	{
		throw RawlogError(path_ + ": write failed: " + e.what());
	}
	if (plain_.is_open() && !plain_)
		throw RawlogError(path_ + ": write failed (disk full?)");
	++n_;
}

void RawlogWriter::flush()
{
	if (plain_.is_open()) plain_.flush();
}

void RawlogWriter::close()
{
	if (!open_) return;
	open_ = false;
	arch_.reset();
	if (plain_.is_open()) plain_.close();
	if (gz_.fileOpenCorrectly()) gz_.close();
}

}  // namespace bims
