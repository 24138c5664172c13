// EXR writing (image_io.h write_exr, ExrView, packed): the chunks packed, predicted and deflated
// here on the render's threads and handed to OpenEXR's core library; and write_image, the
// atomic write every image output goes through (image_write.h).
#include "io/image_io.h"
#include "io/image_write.h"

#include <OpenEXR/openexr.h>
#include <libdeflate.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <span>

#include "util/file_io.h"
#include "util/message_text.h"
#include "util/parallel.h"

namespace pb {

void write_image(const std::string& path, const std::function<void(const std::string&)>& write) {
  try {
    write_atomically(path, write, ".exr");
  } catch (const FileError& e) {
    throw ImageError(e.what());
  }
}

namespace {

int index_of(const std::vector<std::string>& channels, const std::string& name) {
  for (size_t c = 0; c < channels.size(); ++c)
    if (channels[c] == name) return int(c);
  return -1;
}

}  // namespace

int ExrImage::channel_index(const std::string& name) const { return index_of(channels, name); }

ExrView::ExrView(const ExrImage& image)
    : width(image.width), height(image.height), channels(image.channels), metadata(image.metadata) {
  // No planes where the pixels do not fill the image: write_exr refuses it.
  const size_t nc = channels.size();
  if (width <= 0 || height <= 0 || image.pixels.size() != size_t(width) * size_t(height) * nc)
    return;
  for (size_t c = 0; c < nc; ++c) planes.push_back({image.pixels.data() + c, nc});
}

int ExrView::channel_index(const std::string& name) const { return index_of(channels, name); }

ExrImage packed(const ExrView& view) {
  ExrImage out;
  out.width = view.width;
  out.height = view.height;
  out.channels = view.channels;
  out.metadata = view.metadata;
  const size_t nc = view.channels.size();
  if (view.width <= 0 || view.height <= 0 || view.planes.size() != nc) return out;  // no pixels
  const size_t pixels = size_t(view.width) * size_t(view.height);
  out.pixels.resize(pixels * nc);
  // Pixel by pixel on every thread, each pixel's channels side by side: channel by channel over
  // the whole image wrote every cache line of the output once per channel.
  parallel_for(pixels, 4096, [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p) {
      float* to = out.pixels.data() + p * nc;
      for (size_t c = 0; c < nc; ++c) to[c] = view.at(c, p);
    }
  });
  return out;
}

namespace {

// A chunk of a scan-line EXR as the file holds it (OpenEXR's ImfZipCompressor): its lines'
// channels in the file's channel order, each channel's row of floats; for ZIP, bytes split
// into even and odd halves, then differences of consecutive bytes, then zlib format, or the
// packed bytes themselves where that would not shrink them (the reader tells the two apart by
// the size, as the format says).
void pack_lines(const ExrView& image, std::span<const size_t> order, int y0, int y1,
                unsigned char* out) {
  const size_t w = size_t(image.width);
  for (int y = y0; y < y1; ++y)
    for (const size_t c : order) {
      const size_t stride = image.planes[c].stride;
      const float* row = image.planes[c].data + size_t(y) * w * stride;
      for (size_t x = 0; x < w; ++x, out += sizeof(float)) std::memcpy(out, row + x * stride, 4);
    }
}

void zip_predict(const unsigned char* raw, size_t n, unsigned char* out) {
  unsigned char* even = out;
  unsigned char* odd = out + (n + 1) / 2;
  size_t i = 0;
  for (; i + 1 < n; i += 2) {
    *even++ = raw[i];
    *odd++ = raw[i + 1];
  }
  if (i < n) *even = raw[i];
  int previous = out[0];
  for (size_t k = 1; k < n; ++k) {
    const int d = int(out[k]) - previous + (128 + 256);
    previous = out[k];
    out[k] = static_cast<unsigned char>(d);
  }
}

struct FreeCompressor {
  void operator()(libdeflate_compressor* c) const { libdeflate_free_compressor(c); }
};

// One chunk of a batch: its bytes as written (the first `size` of `a`), the predictor's
// scratch `b` and a compressor, kept across batches.
struct ChunkSlot {
  std::vector<unsigned char> a, b;
  std::unique_ptr<libdeflate_compressor, FreeCompressor> deflate;
  size_t size = 0;
};

void check(exr_result_t r, const char* what) {
  if (r != EXR_ERR_SUCCESS)
    throw std::runtime_error(std::string(what) + ": " + exr_get_default_error_message(r));
}

}  // namespace

// Through OpenEXR's core library, not the module: a render writes its image without loading
// OpenImageIO. The file is what OpenImageIO wrote before (float channels, sorted by name as EXR
// keeps them, "photonbound:KEY" string attributes), less OpenImageIO's own attributes. ZIP's
// deflate is libdeflate's at its fastest level rather than zlib's inside OpenEXR: the bound,
// noise and variance channels are noise-like floats that deflate shrinks little and slowly
// (a 16-pass 512x512 render's 20 channels: zlib level 1 0.50 s of CPU, libdeflate level 1
// 0.26 s, the files within 0.1% of each other), and the chunks are compressed on the render's
// threads and written in order.
void write_exr(const std::string& path, const ExrView& image, ExrCompression compression) {
  const size_t nc = image.channels.size();
  if (image.width <= 0 || image.height <= 0 || nc == 0 || image.planes.size() != nc ||
      std::any_of(image.planes.begin(), image.planes.end(),
                  [](const ExrView::Plane& p) { return !p.data; }))
    throw ImageError(path + ": cannot write: the image holds no pixels");
  const bool zip = compression == ExrCompression::Zip;
  const int lines = zip ? 16 : 1;  // scan lines per chunk (ZIP's 16; NONE's 1)
  write_image(path, [&](const std::string& tmp) {
    exr_context_t ctx = nullptr;
    try {
      exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
      check(exr_start_write(&ctx, tmp.c_str(), EXR_WRITE_FILE_DIRECTLY, &init), "start");
      int part = 0;
      check(exr_add_part(ctx, "", EXR_STORAGE_SCANLINE, &part), "part");
      check(exr_initialize_required_attr_simple(ctx, part, image.width, image.height,
                                                zip ? EXR_COMPRESSION_ZIP : EXR_COMPRESSION_NONE),
            "header");
      for (const std::string& name : image.channels)
        check(exr_add_channel(ctx, part, name.c_str(), EXR_PIXEL_FLOAT,
                              EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1),
              "channel");
      for (const auto& [key, value] : image.metadata)
        check(exr_attr_set_string(ctx, part, ("photonbound:" + key).c_str(), value.c_str()),
              "attribute");
      check(exr_write_header(ctx), "header");
      // The file's channel order (sorted by name) as indices into the image's.
      const exr_attr_chlist_t* list = nullptr;
      check(exr_get_channels(ctx, part, &list), "channels");
      std::vector<size_t> order;
      for (int i = 0; i < list->num_channels; ++i)
        order.push_back(size_t(image.channel_index(list->entries[i].name.str)));
      const int chunks = (image.height + lines - 1) / lines;
      const size_t chunk_bytes = size_t(image.width) * nc * sizeof(float) * size_t(lines);
      // Chunks in batches of about 4 MB, compressed at once on the render's threads while the
      // batch before is written (in order): the write holds two batches' two buffers (16-20
      // MB) beside the image, not a copy. One batch after the other, a thread idled while the
      // other wrote (0.65 s of which about 0.1 s the writes at 1920x1080).
      // At least two chunks a batch, for the two threads of a machine like ours.
      const size_t per_batch = std::clamp<size_t>((size_t(4) << 20) / chunk_bytes, 2, 64);
      const int batch = int(std::min(per_batch, size_t(chunks)));
      std::vector<ChunkSlot> slots[2];
      for (std::vector<ChunkSlot>& set : slots) {
        set.resize(size_t(batch));
        for (ChunkSlot& slot : set) {
          slot.a.resize(chunk_bytes);
          if (!zip) continue;
          slot.b.resize(chunk_bytes);
          slot.deflate.reset(libdeflate_alloc_compressor(1));
          if (!slot.deflate) throw std::bad_alloc();
        }
      }
      auto count_at = [&](int first) { return std::min(batch, chunks - first); };
      auto compress = [&](int first, std::vector<ChunkSlot>& set) {
        parallel_for(size_t(count_at(first)), 1, [&](size_t begin, size_t end) {
          for (size_t j = begin; j < end; ++j) {
            ChunkSlot& slot = set[j];
            const int y0 = (first + int(j)) * lines, y1 = std::min(image.height, y0 + lines);
            const size_t n = chunk_bytes / size_t(lines) * size_t(y1 - y0);
            pack_lines(image, order, y0, y1, slot.a.data());
            slot.size = n;
            if (!zip) continue;
            zip_predict(slot.a.data(), n, slot.b.data());
            // Room for fewer bytes than the packed ones: 0 when deflate would not shrink them.
            const size_t z = libdeflate_zlib_compress(slot.deflate.get(), slot.b.data(), n,
                                                      slot.a.data(), n - 1);
            if (z > 0)
              slot.size = z;
            else  // stored: the packed bytes again (the compressor wrote over them)
              pack_lines(image, order, y0, y1, slot.a.data());
          }
        });
      };
      auto write = [&](int first, const std::vector<ChunkSlot>& set) {
        for (int j = 0; j < count_at(first); ++j)
          check(exr_write_scanline_chunk(ctx, part, (first + j) * lines, set[size_t(j)].a.data(),
                                         set[size_t(j)].size),
                "chunk");
      };
      compress(0, slots[0]);
      for (int first = 0, k = 0; first < chunks; first += batch, k ^= 1) {
        const int next = first + batch;
        if (next < chunks)
          parallel_invoke([&] { compress(next, slots[k ^ 1]); }, [&] { write(first, slots[k]); });
        else
          write(first, slots[k]);
      }
      check(exr_finish(&ctx), "finish");
    } catch (const std::exception& e) {
      if (ctx) exr_finish(&ctx);
      throw ImageError(path + ": cannot write: " + one_line(e.what()));
    }
  });
}

}  // namespace pb
