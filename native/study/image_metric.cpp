#include "study/image_metric.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "radiosity/color.h"

namespace radiosity {
namespace {

void require_size(int width, int height, const std::string& what) {
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument(what + ": empty image (" + std::to_string(width) + " x " +
                                std::to_string(height) + ")");
  }
}

// IEC 61966-2-1 (sRGB) encoding of a value in [0, 1].
double srgb_encode(double v) {
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

// Normalised Gaussian samples at offsets -r..r, r = ceil(4 sigma).
std::vector<double> gaussian_kernel(double sigma) {
  const int r = std::max(1, static_cast<int>(std::ceil(4.0 * sigma)));
  std::vector<double> k(static_cast<size_t>(2 * r + 1));
  double sum = 0.0;
  for (int i = -r; i <= r; ++i) {
    const double w = std::exp(-0.5 * (i / sigma) * (i / sigma));
    k[static_cast<size_t>(i + r)] = w;
    sum += w;
  }
  for (double& w : k) w /= sum;
  return k;
}

// One 1D pass along rows (dx = 1) or columns (dx = 0), border extended.
GrayImage blur_pass(const GrayImage& in, const std::vector<double>& k, bool along_rows) {
  GrayImage out{in.width, in.height, std::vector<double>(in.values.size())};
  const int r = static_cast<int>(k.size() / 2);
  const int w = in.width, h = in.height;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      double s = 0.0;
      for (int i = -r; i <= r; ++i) {
        const int sx = along_rows ? std::clamp(x + i, 0, w - 1) : x;
        const int sy = along_rows ? y : std::clamp(y + i, 0, h - 1);
        s += k[static_cast<size_t>(i + r)] * in.values[static_cast<size_t>(sy) * w + sx];
      }
      out.values[static_cast<size_t>(y) * w + x] = s;
    }
  }
  return out;
}

void write_floats(const std::string& path, int width, int height, int channels,
                  const std::vector<float>& data) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw std::invalid_argument("cannot write image '" + path + "': " + OIIO::geterror());
  // Float where the format holds it (EXR, TIFF, HDR), else 8 bits (PNG, JPEG).
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  const bool is_float = ext == ".exr" || ext == ".tif" || ext == ".tiff" || ext == ".hdr";
  const OIIO::ImageSpec spec(width, height, channels,
                             is_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  if (!out->open(path, spec))
    throw std::invalid_argument("cannot write image '" + path + "': " + out->geterror());
  std::vector<float> clipped;
  const float* pixels = data.data();
  if (!is_float) {
    clipped.resize(data.size());
    std::transform(data.begin(), data.end(), clipped.begin(),
                   [](float v) { return std::clamp(v, 0.0f, 1.0f); });
    pixels = clipped.data();
  }
  const bool ok = out->write_image(OIIO::TypeDesc::FLOAT, pixels);
  const std::string error = out->geterror();
  out->close();
  if (!ok) throw std::invalid_argument("cannot write image '" + path + "': " + error);
}

}  // namespace

RgbImage read_rgb_image(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw std::invalid_argument("image file not found: '" + path + "'");
  }
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw std::invalid_argument("cannot read image '" + path + "': " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  require_size(spec.width, spec.height, "image '" + path + "'");
  const int channels = spec.nchannels;
  std::vector<float> all(static_cast<size_t>(spec.width) * spec.height * channels);
  if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, all.data())) {
    throw std::invalid_argument("cannot read image '" + path + "': " + in->geterror());
  }
  RgbImage img{spec.width, spec.height,
               std::vector<float>(static_cast<size_t>(spec.width) * spec.height * 3)};
  for (size_t p = 0; p < static_cast<size_t>(spec.width) * spec.height; ++p) {
    for (int c = 0; c < 3; ++c) {
      img.rgb[3 * p + c] = all[p * channels + (channels >= 3 ? c : 0)];
    }
  }
  return img;
}

void write_gray_image(const std::string& path, const GrayImage& image) {
  require_size(image.width, image.height, "write_gray_image");
  write_floats(path, image.width, image.height, 1,
               std::vector<float>(image.values.begin(), image.values.end()));
}

void write_rgb_image(const std::string& path, const RgbImage& image) {
  require_size(image.width, image.height, "write_rgb_image");
  write_floats(path, image.width, image.height, 3, image.rgb);
}

GrayImage brightness(const RgbImage& image, BrightnessEncoding encoding) {
  GrayImage out{image.width, image.height, std::vector<double>(image.rgb.size() / 3)};
  for (size_t p = 0; p < out.values.size(); ++p) {
    const double y = luminance(Rgb(image.rgb[3 * p], image.rgb[3 * p + 1], image.rgb[3 * p + 2]));
    out.values[p] =
        encoding == BrightnessEncoding::Linear ? y : srgb_encode(std::clamp(y, 0.0, 1.0));
  }
  return out;
}

GrayImage gaussian_blur(const GrayImage& image, double sigma) {
  if (!(sigma > 0.0) || !std::isfinite(sigma)) {
    throw std::invalid_argument("sigma must be positive and finite, got " + std::to_string(sigma));
  }
  require_size(image.width, image.height, "gaussian_blur");
  const auto k = gaussian_kernel(sigma);
  return blur_pass(blur_pass(image, k, true), k, false);
}

GrayImage difference_of_gaussians(const GrayImage& image, double sigma_center,
                                  double sigma_surround) {
  if (!(sigma_surround > sigma_center)) {
    throw std::invalid_argument("sigma_surround must exceed sigma_center (" +
                                std::to_string(sigma_surround) +
                                " <= " + std::to_string(sigma_center) + ")");
  }
  GrayImage out = gaussian_blur(image, sigma_center);
  const GrayImage surround = gaussian_blur(image, sigma_surround);
  for (size_t i = 0; i < out.values.size(); ++i) out.values[i] -= surround.values[i];
  return out;
}

EdgeFilterSigmas default_edge_sigmas(int width) {
  require_size(width, 1, "default_edge_sigmas");
  // Centre: 1/160 of the width (2 px at 320, 4 px at 640), so the filter
  // responds to the same features at any snapshot size, and is wide enough to
  // be sampled well (>= 1 px) down to 160-pixel snapshots. Surround 1.6 times
  // wider: the ratio at which a difference of Gaussians approximates the
  // Laplacian of Gaussian (Marr and Hildreth), an edge detector.
  const double center = width / 160.0;
  return {center, 1.6 * center};
}

double rms_difference(const GrayImage& a, const GrayImage& b) {
  if (a.width != b.width || a.height != b.height) {
    throw std::invalid_argument("images differ in size: " + std::to_string(a.width) + " x " +
                                std::to_string(a.height) + " and " + std::to_string(b.width) +
                                " x " + std::to_string(b.height));
  }
  require_size(a.width, a.height, "rms_difference");
  double sum = 0.0;
  for (size_t i = 0; i < a.values.size(); ++i) {
    const double d = a.values[i] - b.values[i];
    sum += d * d;
  }
  return std::sqrt(sum / static_cast<double>(a.values.size()));
}

}  // namespace radiosity
