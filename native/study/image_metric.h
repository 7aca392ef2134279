// The image-quality measure of Section 6.2.3 (eq. 24): a snapshot of a
// solution is reduced to brightness, passed through a centre-surround
// (difference of Gaussians) edge filter, and compared with the equally
// filtered reference by the RMS of the pixel differences. The plain,
// unfiltered RMS is the same comparison without the filter.
//
// Images are read and written with OpenImageIO (linear float, e.g. OpenEXR as
// Blender writes it). Bad input (missing file, mismatched sizes, bad sigmas)
// throws std::invalid_argument, which the bindings raise as ValueError.
#pragma once

#include <string>
#include <vector>

namespace radiosity {

// Row-major RGB, top row first, linear.
struct RgbImage {
  int width = 0, height = 0;
  std::vector<float> rgb;  // 3 * width * height
};

// One value per pixel, row-major, top row first.
struct GrayImage {
  int width = 0, height = 0;
  std::vector<double> values;
};

// How a linear radiance becomes the brightness the metric compares.
enum class BrightnessEncoding {
  Linear,   // Rec. 709 luminance of the linear value, unclipped
  Display,  // luminance clipped to [0, 1] (what the Standard view shows), sRGB-encoded:
            // the pixel value a display is driven with, as the source's framebuffer
};

// Reads the first three channels (a one- or two-channel image is grey: its
// first channel is repeated) as linear float.
RgbImage read_rgb_image(const std::string& path);

// Writes a grey image (one channel) or an RGB image; the file type follows the
// extension (float for .exr, 8-bit for .png, values then clipped to [0, 1]).
void write_gray_image(const std::string& path, const GrayImage& image);
void write_rgb_image(const std::string& path, const RgbImage& image);

GrayImage brightness(const RgbImage& image, BrightnessEncoding encoding);

// Separable Gaussian blur, the kernel sampled at whole-pixel offsets out to
// 4 sigma and normalised to sum 1; edges are extended (the border pixel is
// repeated), so a constant image stays constant and the frame is not an edge.
GrayImage gaussian_blur(const GrayImage& image, double sigma);

// Centre-surround filter: blur(sigma_center) - blur(sigma_surround), with
// sigma_surround > sigma_center > 0 (pixels).
GrayImage difference_of_gaussians(const GrayImage& image, double sigma_center,
                                  double sigma_surround);

// The default sigmas for an image `width` pixels wide, relative to the width so
// that a smaller snapshot of the same view gives a comparable number.
struct EdgeFilterSigmas {
  double center, surround;
};
EdgeFilterSigmas default_edge_sigmas(int width);

// Eq. 24: sqrt(mean((a - b)^2)); the images must have equal sizes.
double rms_difference(const GrayImage& a, const GrayImage& b);

}  // namespace radiosity
