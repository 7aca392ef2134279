// The study-only module `_image_metric` (bench/, tests): the image-quality
// measure (study/image_metric.h) for Python: reading and writing linear images,
// brightness, the centre-surround filter, eq. 24, and one call that scores a
// snapshot against a reference from their files. It is built beside the add-on,
// never shipped in it: OpenImageIO, which it needs, is no dependency of the
// solver (`_radiosity`).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>

#include "python/numpy_input.h"
#include "study/image_metric.h"

namespace py = pybind11;

namespace radiosity::python {
namespace {

BrightnessEncoding read_encoding(const std::string& name) {
  if (name == "display") return BrightnessEncoding::Display;
  if (name == "linear") return BrightnessEncoding::Linear;
  throw std::invalid_argument("encoding must be 'display' or 'linear', got '" + name + "'");
}

GrayImage gray_from(const py::handle& object, const std::string& name) {
  const auto a = read_array_of<double>(object, name, {-1, -1});
  GrayImage g{static_cast<int>(a.shape(1)), static_cast<int>(a.shape(0)),
              std::vector<double>(a.data(), a.data() + a.size())};
  if (g.values.empty()) throw std::invalid_argument(name + " is empty");
  return g;
}

RgbImage rgb_from(const py::handle& object, const std::string& name) {
  const auto a = read_array_of<float>(object, name, {-1, -1, 3});
  RgbImage img{static_cast<int>(a.shape(1)), static_cast<int>(a.shape(0)),
               std::vector<float>(a.data(), a.data() + a.size())};
  if (img.rgb.empty()) throw std::invalid_argument(name + " is empty");
  return img;
}

py::array_t<double> to_numpy(const GrayImage& g) {
  py::array_t<double> out({g.height, g.width});
  std::copy(g.values.begin(), g.values.end(), out.mutable_data());
  return out;
}

EdgeFilterSigmas sigmas_for(int width, std::optional<double> center,
                            std::optional<double> surround) {
  EdgeFilterSigmas s = default_edge_sigmas(width);
  if (center) {
    // A given centre keeps the default ratio unless the surround is given too.
    s.surround = *center * (s.surround / s.center);
    s.center = *center;
  }
  if (surround) s.surround = *surround;
  return s;
}

py::dict image_errors(const std::string& test, const std::string& reference,
                      const std::string& encoding, std::optional<double> sigma_center,
                      std::optional<double> sigma_surround,
                      std::optional<std::string> filtered_output) {
  const auto mode = read_encoding(encoding);
  const RgbImage t = read_rgb_image(test);
  const RgbImage r = read_rgb_image(reference);
  if (t.width != r.width || t.height != r.height) {
    throw std::invalid_argument("images differ in size: '" + test + "' is " +
                                std::to_string(t.width) + " x " + std::to_string(t.height) + ", '" +
                                reference + "' is " + std::to_string(r.width) + " x " +
                                std::to_string(r.height));
  }
  const GrayImage bt = brightness(t, mode), br = brightness(r, mode);
  const EdgeFilterSigmas s = sigmas_for(t.width, sigma_center, sigma_surround);
  const GrayImage ft = difference_of_gaussians(bt, s.center, s.surround);
  const GrayImage fr = difference_of_gaussians(br, s.center, s.surround);
  if (filtered_output) write_gray_image(*filtered_output, ft);
  py::dict d;
  d["dog"] = rms_difference(ft, fr);
  d["rms"] = rms_difference(bt, br);
  d["width"] = t.width;
  d["height"] = t.height;
  d["sigma_center"] = s.center;
  d["sigma_surround"] = s.surround;
  return d;
}

void bind_image_metric(py::module_& m) {
  m.def(
      "read_image",
      [](const std::string& path) {
        const RgbImage img = read_rgb_image(path);
        py::array_t<float> out({img.height, img.width, 3});
        std::copy(img.rgb.begin(), img.rgb.end(), out.mutable_data());
        return out;
      },
      py::arg("path"),
      "(H, W, 3) float32 linear RGB of an image file (top row first), via OpenImageIO.");

  m.def(
      "write_image",
      [](const std::string& path, const py::handle& image) {
        const auto a = py::array::ensure(image);
        if (a && a.ndim() == 2) {
          write_gray_image(path, gray_from(image, "image"));
        } else {
          write_rgb_image(path, rgb_from(image, "image"));
        }
      },
      py::arg("path"), py::arg("image"),
      "Write an (H, W) or (H, W, 3) image: float for .exr/.tif/.hdr, else 8-bit clipped to [0, "
      "1].");

  m.def(
      "brightness",
      [](const py::handle& image, const std::string& encoding) {
        return to_numpy(brightness(rgb_from(image, "image"), read_encoding(encoding)));
      },
      py::arg("image"), py::arg("encoding") = "display",
      "Brightness (H, W) of a linear RGB image: Rec. 709 luminance; 'display' clips it to [0, 1]\n"
      "and sRGB-encodes it (the value on screen), 'linear' leaves it as it is.");

  m.def(
      "edge_filter_sigmas",
      [](int width) {
        const auto s = default_edge_sigmas(width);
        return py::make_tuple(s.center, s.surround);
      },
      py::arg("width"), "(sigma_center, sigma_surround) in pixels for an image this wide.");

  m.def(
      "gaussian_blur",
      [](const py::handle& gray, double sigma) {
        return to_numpy(gaussian_blur(gray_from(gray, "image"), sigma));
      },
      py::arg("image"), py::arg("sigma"), "Separable Gaussian blur, borders extended.");

  m.def(
      "dog_filter",
      [](const py::handle& gray, std::optional<double> sigma_center,
         std::optional<double> sigma_surround) {
        const GrayImage g = gray_from(gray, "image");
        const auto s = sigmas_for(g.width, sigma_center, sigma_surround);
        return to_numpy(difference_of_gaussians(g, s.center, s.surround));
      },
      py::arg("image"), py::arg("sigma_center") = py::none(),
      py::arg("sigma_surround") = py::none(),
      "Centre-surround (difference of Gaussians) filter of an (H, W) brightness image;\n"
      "sigmas in pixels, default edge_filter_sigmas(W).");

  m.def(
      "rms_difference",
      [](const py::handle& a, const py::handle& b) {
        return rms_difference(gray_from(a, "a"), gray_from(b, "b"));
      },
      py::arg("a"), py::arg("b"),
      "Eq. 24: RMS of the pixel differences of two equal-sized (H, W) images.");

  m.def(
      "image_errors", &image_errors, py::arg("test"), py::arg("reference"),
      py::arg("encoding") = "display", py::arg("sigma_center") = py::none(),
      py::arg("sigma_surround") = py::none(), py::arg("filtered_output") = py::none(),
      "Score the image file `test` against `reference` (Section 6.2.3): dict with 'dog' (eq. 24 "
      "on\n"
      "the centre-surround filtered brightness), 'rms' (unfiltered brightness), the size and the\n"
      "sigmas used. filtered_output: also write test's filtered brightness there.");
}

}  // namespace
}  // namespace radiosity::python

PYBIND11_MODULE(_image_metric, m) {
  m.doc() = "Image-quality measure of the speed-accuracy study (Section 6.2.3), with OpenImageIO";
  radiosity::python::bind_image_metric(m);
}
