// A decompression bomb for the image readers' tests: a PNG of a few hundred
// bytes whose header declares a huge image (a decoder that trusts it
// allocates width x height x 8 bytes before reading a row).
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace bims::test
{
inline uint32_t crc32Png(const uint8_t* p, size_t n)
{
	uint32_t c = 0xffffffffu;
	for (size_t i = 0; i < n; ++i)
	{
		c ^= p[i];
		for (int k = 0; k < 8; ++k)
			c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
	}
	return c ^ 0xffffffffu;
}

/** Writes to \a path a valid PNG header declaring \a width x \a height RGBA
 * 16-bit, a tiny zlib stream of zeros as its data, and IEND. */
inline void writePngBomb(const std::string& path, uint32_t width = 30000,
                         uint32_t height = 30000)
{
	std::vector<uint8_t> out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
	const auto be32 = [](std::vector<uint8_t>& v, uint32_t x)
	{
		for (int s = 24; s >= 0; s -= 8) v.push_back(uint8_t(x >> s));
	};
	const auto chunk = [&](const char* type, const std::vector<uint8_t>& data)
	{
		be32(out, static_cast<uint32_t>(data.size()));
		std::vector<uint8_t> body(type, type + 4);
		body.insert(body.end(), data.begin(), data.end());
		out.insert(out.end(), body.begin(), body.end());
		be32(out, crc32Png(body.data(), body.size()));
	};
	std::vector<uint8_t> ihdr;
	be32(ihdr, width);
	be32(ihdr, height);
	ihdr.insert(ihdr.end(), {16, 6, 0, 0, 0});  // 16-bit RGBA
	chunk("IHDR", ihdr);
	// a minimal zlib stream without pixels: a decoder that trusts the
	// header fails only after allocating the image
	chunk("IDAT", {0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01});
	chunk("IEND", {});
	std::ofstream(path, std::ios::binary)
	    .write(reinterpret_cast<const char*>(out.data()),
	           static_cast<std::streamsize>(out.size()));
}
}  // namespace bims::test
