// Writes the fuzz targets' seed inputs (docs/fuzz.md):
//   fuzz_make_seeds SAMPLE.rawlog OUT_DIR
// OUT_DIR/rawlog: the sample's first scans shrunk to 32 x 24 (depth,
// intensity, camera models) with the IMU samples between them, plain;
// OUT_DIR/labels and OUT_DIR/tum: small hand-made inputs of each kind;
// OUT_DIR/bag: ROS 1 bags of the sample's first 3 scans shrunk so, in each
// layout, raw and compressed (compressedDepth PNG and RVL), plain and LZ4 / BZ2
// chunks (when bims-import-bag is built).
#include <bims/io/rawlog.h>

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>

#include <opencv2/imgcodecs.hpp>

#ifdef BIMS_FUZZ_BAG_SEEDS
#include <bims_test/bag_writer.h>
#endif

#include <filesystem>
#include <fstream>
#include <iostream>

namespace
{
void shrink(mrpt::obs::CObservation3DRangeScan& s, int W, int H)
{
	const int w0 = static_cast<int>(s.rangeImage.cols()),
	          h0 = static_cast<int>(s.rangeImage.rows());
	const mrpt::math::CMatrix_u16 r = s.rangeImage;
	s.rangeImage_setSize(H, W);
	for (int v = 0; v < H; v++)
		for (int u = 0; u < W; u++)
			s.rangeImage(v, u) = r(v * h0 / H, u * w0 / W);
	mrpt::img::CImage small;
	s.intensityImage.scaleImage(small, W, H);
	s.intensityImage = small;
	const double k = double(W) / w0;
	for (auto* c : {&s.cameraParams, &s.cameraParamsIntensity})
	{
		c->setIntrinsicParamsFromValues(c->fx() * k, c->fy() * k, c->cx() * k,
		                                c->cy() * k);
		c->ncols = W;
		c->nrows = H;
	}
	s.pixelLabels.reset();
}

#ifdef BIMS_FUZZ_BAG_SEEDS
/** Bags of the sample's first 3 scans, shrunk to 32 x 24, and the IMU
 * samples up to the third, each well under fuzz.sh's 64 kB inputs. */
void writeBagSeeds(const std::string& sample, const std::filesystem::path& dir)
{
	using namespace mrpt::obs;
	std::vector<CObservation3DRangeScan::Ptr> frames;
	std::vector<CObservationIMU::Ptr> imu;
	bims::RawlogReader in(sample);
	while (frames.size() < 3)
	{
		const auto o = in.next();
		if (!o) break;
		if (auto s = std::dynamic_pointer_cast<CObservation3DRangeScan>(o))
		{
			s->load();
			shrink(*s, 32, 24);
			frames.push_back(s);
		}
		else if (auto m = std::dynamic_pointer_cast<CObservationIMU>(o))
			imu.push_back(m);
	}
	using bims::test::BagSpec;
	const auto lz4 = rosbag::compression::LZ4, bz2 = rosbag::compression::BZ2;
	struct Seed
	{
		const char* name;
		BagSpec spec;
	};
	std::vector<Seed> seeds;
	auto add = [&](const char* name, bool tum, const char* codec,
	               bool compressedDepth, rosbag::compression::CompressionType c,
	               bool split, const char* depthCodec = "png")
	{
		BagSpec s;
		s.tum = tum;
		s.colourCodec = codec;
		s.compressedDepth = compressedDepth;
		s.depthCodec = depthCodec;
		s.compression = c;
		s.splitImu = split;
		s.frames = frames.size();
		seeds.push_back({name, s});
	};
	const auto plain = rosbag::compression::Uncompressed;
	add("realsense-raw.bag", false, "", false, plain, false);
	add("realsense-split-imu-lz4.bag", false, "", false, lz4, true);
	add("realsense-jpeg-compresseddepth.bag", false, "jpeg", true, plain,
	    false);
	add("realsense-png-compresseddepth-bz2.bag", false, "png", true, bz2, true);
	add("tum-raw.bag", true, "", false, plain, false);
	add("tum-png-compresseddepth.bag", true, "png", true, plain, false);
	// RVL depth in plain chunks: its stream is what the mutations reach
	add("realsense-rvl-compresseddepth.bag", false, "", true, plain, false,
	    "rvl");
	add("tum-rvl-compresseddepth.bag", true, "", true, plain, false, "rvl");
	for (const auto& s : seeds)
		bims::test::writeBag((dir / s.name).string(), s.spec, frames, imu);
}
#endif

void writeText(const std::filesystem::path& p, const std::string& text)
{
	std::ofstream f(p, std::ios::binary);
	f << text;
	if (!f) throw std::runtime_error(p.string() + ": cannot write");
}
}  // namespace

int main(int argc, char** argv)
{
	namespace fs = std::filesystem;
	if (argc != 3)
	{
		std::cerr << "usage: fuzz_make_seeds SAMPLE.rawlog OUT_DIR\n";
		return 2;
	}
	try
	{
		const fs::path out = argv[2];
		for (const char* d : {"rawlog", "labels", "tum", "image", "stray"})
			fs::create_directories(out / d);
#ifdef BIMS_FUZZ_BAG_SEEDS
		fs::create_directories(out / "bag");
		writeBagSeeds(argv[1], out / "bag");
#endif
		{
			bims::RawlogReader in(argv[1]);
			bims::RawlogWriter w(
			    (out / "rawlog" / "sample_head.rawlog").string(), 0);
			int scans = 0;
			while (scans < 2)
			{
				const auto o = in.next();
				if (!o) break;
				if (auto s = std::dynamic_pointer_cast<
				        mrpt::obs::CObservation3DRangeScan>(o))
				{
					shrink(*s, 32, 24);
					++scans;
				}
				w.write(*o);
			}
			w.close();
		}
		cv::Mat lab(6, 8, CV_8UC1, cv::Scalar(0));
		lab(cv::Rect(2, 1, 3, 3)).setTo(255);
		lab.col(7).setTo(150);
		lab.row(5).setTo(50);
		std::vector<uint8_t> png;
		cv::imencode(".png", lab, png);
		png.insert(png.begin(), 0);
		std::ofstream(out / "labels" / "png", std::ios::binary)
		    .write(reinterpret_cast<const char*>(png.data()),
		           static_cast<std::streamsize>(png.size()));
		writeText(out / "labels" / "frames_csv",
		          std::string(1, '\1') +
		              "index,t,ego_flags\n0,1548339824.89375,1\n1,"
		              "1548339824.9275,2048\n");
		writeText(out / "labels" / "values", std::string(1, '\2') + "150,50");
		writeText(out / "tum" / "folder",
		          "# rgb\n1.0 rgb/1.0.png\n1.033 rgb/1.033.png\n--\n# depth\n"
		          "1.001 depth/1.001.png\n1.034 depth/1.034.png\n--\n"
		          "# timestamp tx ty tz qx qy qz qw\n"
		          "1.0 0 0 0 0 0 0 1\n1.04 0.01 0 0 0 0 0 1\n--\n"
		          "1.0 0 0 9.81\n");
		// one small image of each kind the readers meet: 16-bit depth PNG,
		// colour PNG and JPEG, TIFF, BMP
		cv::Mat depth(6, 8, CV_16UC1, cv::Scalar(1234));
		depth(cv::Rect(0, 0, 3, 2)).setTo(0);
		cv::Mat colour(6, 8, CV_8UC3, cv::Scalar(30, 120, 200));
		const std::pair<const char*, const cv::Mat*> images[] = {
		    {"depth.png", &depth},
		    {"colour.png", &colour},
		    {"colour.jpg", &colour},
		    {"colour.tiff", &colour},
		    {"colour.bmp", &colour}};
		for (const auto& [name, img] : images)
		{
			std::vector<uint8_t> bytes;
			const std::string n = name;
			cv::imencode(n.substr(n.find('.')), *img, bytes);
			std::ofstream(out / "image" / name, std::ios::binary)
			    .write(reinterpret_cast<const char*>(bytes.data()),
			           static_cast<std::streamsize>(bytes.size()));
		}
		writeText(out / "stray" / "capture",
		          "timestamp, frame, x, y, z, qx, qy, qz, qw\n"
		          "0.5, 000000, 0, 0, 0, 0, 0, 0, 1\n"
		          "0.516, 000001, 0.01, 0, 0, 0, 0, 0.0087, 0.99996\n--\n"
		          "timestamp, a_x, a_y, a_z, alpha_x, alpha_y, alpha_z\n"
		          "0.49, 0.01, -1.0, 0.02, 0.1, 0, 0\n"
		          "0.50, 0.01, -0.99, 0.02, 0.1, 0.01, 0\n--\n"
		          "1400.0, 0.0, 960.0\n0.0, 1400.0, 720.0\n0.0, 0.0, 1.0\n");
		std::cout << "seeds in " << out.string() << "\n";
	}
	catch (const std::exception& e)
	{
		std::cerr << "fuzz_make_seeds: " << e.what() << "\n";
		return 1;
	}
	return 0;
}
