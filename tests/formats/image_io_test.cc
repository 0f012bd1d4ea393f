#include "formats/image_io.h"

#include <gtest/gtest.h>
#include <libdeflate.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

class ImageIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("puzzlecal_image_io_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // A grey ramp with a known value at (10, 20).
    ramp_ = cv::Mat(40, 60, CV_8UC1);
    for (int y = 0; y < ramp_.rows; ++y) {
      for (int x = 0; x < ramp_.cols; ++x) ramp_.at<uint8_t>(y, x) = 3 * x + y;
    }
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Path(const std::string& name) const {
    return (dir_ / name).string();
  }

  void WriteBytes(const std::string& name, const std::string& bytes) const {
    std::ofstream(Path(name), std::ios::binary) << bytes;
  }

  std::string ReadBytes(const std::string& name) const {
    std::ifstream in(Path(name), std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

  fs::path dir_;
  cv::Mat ramp_;
};

TEST_F(ImageIoTest, ListsImagesSortedAndSkipsOthers) {
  cv::imwrite(Path("b.png"), ramp_);
  cv::imwrite(Path("a.JPG"), ramp_);
  WriteBytes("notes.txt", "hello");
  ImageListing listing;
  std::string error;
  ASSERT_TRUE(ListImages(dir_.string(), &listing, &error)) << error;
  ASSERT_EQ(listing.images.size(), 2u);
  EXPECT_EQ(fs::path(listing.images[0]).filename(), "a.JPG");
  EXPECT_EQ(fs::path(listing.images[1]).filename(), "b.png");
  ASSERT_EQ(listing.skipped.size(), 1u);
  EXPECT_NE(listing.skipped[0].find("notes.txt"), std::string::npos);
}

TEST_F(ImageIoTest, MissingAndEmptyFoldersNameThePath) {
  ImageListing listing;
  std::string error;
  EXPECT_FALSE(ListImages(Path("missing"), &listing, &error));
  EXPECT_NE(error.find("missing"), std::string::npos);
  EXPECT_NE(error.find("no such"), std::string::npos);
  fs::create_directories(Path("empty"));
  EXPECT_FALSE(ListImages(Path("empty"), &listing, &error));
  EXPECT_NE(error.find("empty"), std::string::npos);
  EXPECT_NE(error.find("no image"), std::string::npos);
}

// A folder whose images are all in sub-folders (a rig's camera folders):
// the message names the sub-folders, counts their images and points to
// calibrate-rig or to one of them. It said only "holds no image files".
TEST_F(ImageIoTest, FolderOfImageFoldersSaysWhereTheImagesAre) {
  for (const char* camera : {"cam0", "cam1"}) {
    fs::create_directories(dir_ / camera);
    for (const char* name : {"01.png", "02.png"}) {
      cv::imwrite((dir_ / camera / name).string(), ramp_);
    }
  }
  fs::create_directories(dir_ / "notes");  // no images: not named
  WriteBytes("notes/readme.txt", "hello");
  ImageListing listing;
  std::string error;
  EXPECT_FALSE(ListImages(dir_.string(), &listing, &error));
  EXPECT_EQ(error.rfind(dir_.string() + ": the folder holds no image files", 0),
            0u)
      << error;
  EXPECT_NE(error.find("its sub-folders cam0 and cam1 hold 4 image files "
                       "(sub-folders are not searched)"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("use calibrate-rig, otherwise point --images at one "
                       "of them"),
            std::string::npos)
      << error;
  EXPECT_EQ(error.find("notes"), std::string::npos) << error;
  // One sub-folder, said as one.
  fs::remove_all(dir_ / "cam1");
  EXPECT_FALSE(ListImages(dir_.string(), &listing, &error));
  EXPECT_NE(error.find("its sub-folder cam0 holds 2 image files"),
            std::string::npos)
      << error;
}

// Photos in formats that are not read (HEIC, camera RAW): alone, the
// message counts them by format and says to convert them; beside images
// that are read, the listing's note says in one line how many were skipped
// and why (they were skipped silently).
TEST_F(ImageIoTest, PhotosInFormatsNotReadAreCountedByFormat) {
  for (const char* name : {"IMG_0001.HEIC", "IMG_0002.HEIC", "IMG_0003.heic",
                           "DSC_0004.NEF", "notes.txt"}) {
    WriteBytes(name, "not decoded");
  }
  ImageListing listing;
  std::string error;
  EXPECT_FALSE(ListImages(dir_.string(), &listing, &error));
  EXPECT_NE(error.find("no image files"), std::string::npos) << error;
  EXPECT_NE(error.find("it holds 3 HEIC files and 1 NEF file (HEIC/HEIF, RAW "
                       "and the like are not read): convert them to JPEG or "
                       "PNG"),
            std::string::npos)
      << error;
  EXPECT_EQ(error.find("sub-folder"), std::string::npos) << error;

  cv::imwrite(Path("a.png"), ramp_);
  ASSERT_TRUE(ListImages(dir_.string(), &listing, &error)) << error;
  ASSERT_EQ(listing.images.size(), 1u);
  EXPECT_EQ(listing.unread_photos.size(), 4u);
  EXPECT_EQ(listing.skipped.size(), 5u);  // notes.txt too
  EXPECT_EQ(listing.note, dir_.string() +
                              ": skipped 3 HEIC files and 1 NEF file "
                              "(HEIC/HEIF, RAW and the like are not read): "
                              "convert them to JPEG or PNG to use them");
  EXPECT_TRUE(HasUnreadPhotoExtension("x.Cr2"));
  EXPECT_TRUE(HasUnreadPhotoExtension("x.dng"));
  EXPECT_FALSE(HasUnreadPhotoExtension("x.jpg"));
  EXPECT_FALSE(HasUnreadPhotoExtension("x.txt"));

  // Only images that are read: no note.
  for (const std::string& file : listing.unread_photos) fs::remove(file);
  ASSERT_TRUE(ListImages(dir_.string(), &listing, &error)) << error;
  EXPECT_EQ(listing.note, "");
}

TEST_F(ImageIoTest, LoadsEightBitGreyExactly) {
  cv::imwrite(Path("ramp.png"), ramp_);
  cv::Mat grey;
  std::string error;
  ASSERT_TRUE(LoadGreyImage(Path("ramp.png"), {}, &grey, &error)) << error;
  EXPECT_EQ(grey.type(), CV_8UC1);
  EXPECT_EQ(cv::norm(grey, ramp_, cv::NORM_INF), 0.0);
}

TEST_F(ImageIoTest, ConvertsColourRgbaAndSixteenBit) {
  cv::Mat bgr, bgra, deep;
  cv::cvtColor(ramp_, bgr, cv::COLOR_GRAY2BGR);
  cv::cvtColor(ramp_, bgra, cv::COLOR_GRAY2BGRA);
  ramp_.convertTo(deep, CV_16U, 16.0);  // a 12-bit camera in 16-bit words
  cv::imwrite(Path("bgr.png"), bgr);
  cv::imwrite(Path("bgra.png"), bgra);
  cv::imwrite(Path("deep.png"), deep);
  cv::imwrite(Path("deep.tif"), deep);
  for (const char* name : {"bgr.png", "bgra.png", "deep.png", "deep.tif"}) {
    cv::Mat grey;
    std::string error;
    ASSERT_TRUE(LoadGreyImage(Path(name), {}, &grey, &error)) << error;
    EXPECT_EQ(grey.type(), CV_8UC1) << name;
    EXPECT_EQ(grey.size(), ramp_.size()) << name;
    // Grey values keep their order: the brightest pixel stays brightest.
    cv::Point max_at_loaded, max_at_truth;
    cv::minMaxLoc(grey, nullptr, nullptr, nullptr, &max_at_loaded);
    cv::minMaxLoc(ramp_, nullptr, nullptr, nullptr, &max_at_truth);
    EXPECT_EQ(max_at_loaded, max_at_truth) << name;
  }
}

TEST_F(ImageIoTest, RefusesBadFilesWithTheReason) {
  cv::imwrite(Path("good.png"), ramp_);
  cv::imwrite(Path("good.jpg"), ramp_);
  const std::string png = ReadBytes("good.png");
  const std::string jpg = ReadBytes("good.jpg");
  WriteBytes("truncated.png", png.substr(0, png.size() / 2));
  WriteBytes("truncated.jpg", jpg.substr(0, jpg.size() / 2));
  WriteBytes("zero.png", "");
  WriteBytes("text.png", "this is not an image at all");
  struct Case {
    const char* file;
    const char* reason;
  };
  for (const Case& c :
       {Case{"truncated.png", "truncated PNG"},
        Case{"truncated.jpg", "truncated JPEG"}, Case{"zero.png", "empty file"},
        Case{"text.png", "not a readable image"},
        Case{"absent.png", "cannot open"}}) {
    cv::Mat grey;
    std::string error;
    EXPECT_FALSE(LoadGreyImage(Path(c.file), {}, &grey, &error)) << c.file;
    EXPECT_NE(error.find(c.file), std::string::npos) << error;
    EXPECT_NE(error.find(c.reason), std::string::npos) << error;
    EXPECT_TRUE(grey.empty());
  }
}

// Phone JPEGs: an EXIF thumbnail (a complete JPEG inside APP1) before the
// image and data appended after its end-of-image marker. The file loads with
// the trailer; with the main image cut in half it is refused although the
// thumbnail inside it is complete.
TEST_F(ImageIoTest, JpegWithThumbnailAndTrailer) {
  cv::imwrite(Path("main.jpg"), ramp_);
  cv::Mat small;
  cv::resize(ramp_, small, cv::Size(15, 10));
  cv::imwrite(Path("thumb.jpg"), small);
  const std::string main_jpg = ReadBytes("main.jpg");
  const std::string payload =
      std::string("Exif\0\0", 6) + ReadBytes("thumb.jpg");
  const size_t length = payload.size() + 2;
  ASSERT_LT(length, 65536u);
  const std::string app1 = std::string("\xFF\xE1") +
                           static_cast<char>(length >> 8) +
                           static_cast<char>(length & 0xFF) + payload;
  const std::string with_thumbnail =
      main_jpg.substr(0, 2) + app1 + main_jpg.substr(2);
  std::string trailer(3000, '\0');
  for (size_t k = 0; k < trailer.size(); ++k) {
    trailer[k] = static_cast<char>((k * 7919 + 13) >> 2);  // includes FF DA
  }
  WriteBytes("phone.jpg", with_thumbnail + trailer);
  WriteBytes("cut.jpg", with_thumbnail.substr(
                            0, app1.size() + 2 + (main_jpg.size() - 2) / 2));
  cv::Mat grey;
  std::string error;
  ASSERT_TRUE(LoadGreyImage(Path("phone.jpg"), {}, &grey, &error)) << error;
  EXPECT_EQ(grey.size(), ramp_.size());
  EXPECT_FALSE(LoadGreyImage(Path("cut.jpg"), {}, &grey, &error));
  EXPECT_NE(error.find("truncated JPEG"), std::string::npos) << error;
}

// A JPEG whose EXIF orientation tag says "rotate 90 degrees" (6) loads in
// the sensor's frame, as stored: calibration needs that frame.
TEST_F(ImageIoTest, JpegExifOrientationIsNotApplied) {
  cv::Mat colour;
  cv::cvtColor(ramp_, colour, cv::COLOR_GRAY2BGR);
  cv::imwrite(Path("plain.jpg"), colour, {cv::IMWRITE_JPEG_QUALITY, 100});
  const std::string jpg = ReadBytes("plain.jpg");
  // APP1: "Exif\0\0", big-endian TIFF header, one IFD entry 0x0112
  // (orientation), SHORT, count 1, value 6; no next IFD.
  const std::string tiff =
      std::string("MM\0*\0\0\0\x08", 8) + std::string("\0\x01", 2) +
      std::string("\x01\x12\0\x03\0\0\0\x01\0\x06\0\0", 12) +
      std::string("\0\0\0\0", 4);
  const std::string payload = std::string("Exif\0\0", 6) + tiff;
  const size_t length = payload.size() + 2;
  const std::string app1 = std::string("\xFF\xE1") +
                           static_cast<char>(length >> 8) +
                           static_cast<char>(length & 0xFF) + payload;
  WriteBytes("rotated.jpg", jpg.substr(0, 2) + app1 + jpg.substr(2));
  // The tag is real: OpenCV's default reading turns the image.
  ASSERT_EQ(cv::imread(Path("rotated.jpg"), cv::IMREAD_GRAYSCALE).size(),
            cv::Size(ramp_.rows, ramp_.cols));
  cv::Mat grey;
  std::string error;
  ASSERT_TRUE(LoadGreyImage(Path("rotated.jpg"), {}, &grey, &error)) << error;
  ASSERT_EQ(grey.size(), ramp_.size());
  cv::Mat difference;
  cv::absdiff(grey, ramp_, difference);
  EXPECT_LE(cv::norm(difference, cv::NORM_INF), 3.0);
}

// A PNG whose header claims 20000 x 20000 pixels is refused from the header,
// before any decoding (the file holds no image data at all).
TEST_F(ImageIoTest, RefusesAHugePngFromItsHeader) {
  auto big_endian = [](uint32_t v) {
    return std::string{static_cast<char>(v >> 24), static_cast<char>(v >> 16),
                       static_cast<char>(v >> 8), static_cast<char>(v)};
  };
  const std::string png = std::string("\x89PNG\r\n\x1a\n", 8) + big_endian(13) +
                          "IHDR" + big_endian(20000) + big_endian(20000) +
                          std::string("\x08\0\0\0\0", 5) + big_endian(0) +
                          big_endian(0) + "IEND" + big_endian(0xAE426082u);
  WriteBytes("bomb.png", png);
  cv::Mat grey;
  std::string error;
  EXPECT_FALSE(LoadGreyImage(Path("bomb.png"), {}, &grey, &error));
  EXPECT_NE(error.find("20000x20000"), std::string::npos) << error;
  EXPECT_NE(error.find("exceeds"), std::string::npos) << error;
}

// A PNG of `image` (8-bit grey) written here, row y filtered with
// filter(y) (0 None, 1 Sub, 2 Up, 3 Average, 4 Paeth), the data split over
// two IDAT chunks.
std::string GreyPng(const cv::Mat& image, int (*filter)(int)) {
  auto big_endian = [](uint32_t v) {
    return std::string{static_cast<char>(v >> 24), static_cast<char>(v >> 16),
                       static_cast<char>(v >> 8), static_cast<char>(v)};
  };
  auto chunk = [&](const std::string& type, const std::string& data) {
    const std::string body = type + data;
    return big_endian(static_cast<uint32_t>(data.size())) + body +
           big_endian(libdeflate_crc32(0, body.data(), body.size()));
  };
  std::string raw;
  for (int y = 0; y < image.rows; ++y) {
    const int f = filter(y);
    raw += static_cast<char>(f);
    for (int x = 0; x < image.cols; ++x) {
      const int a = x > 0 ? image.at<uint8_t>(y, x - 1) : 0;
      const int b = y > 0 ? image.at<uint8_t>(y - 1, x) : 0;
      const int c = x > 0 && y > 0 ? image.at<uint8_t>(y - 1, x - 1) : 0;
      const int pa = std::abs(b - c), pb = std::abs(a - c),
                pc = std::abs(a + b - 2 * c);
      const int predictor[5] = {0, a, b, (a + b) / 2,
                                pa <= pb && pa <= pc ? a : (pb <= pc ? b : c)};
      raw += static_cast<char>(image.at<uint8_t>(y, x) - predictor[f]);
    }
  }
  libdeflate_compressor* compressor = libdeflate_alloc_compressor(6);
  std::string packed(libdeflate_zlib_compress_bound(compressor, raw.size()),
                     '\0');
  packed.resize(libdeflate_zlib_compress(compressor, raw.data(), raw.size(),
                                         packed.data(), packed.size()));
  libdeflate_free_compressor(compressor);
  const std::string header = big_endian(image.cols) + big_endian(image.rows) +
                             std::string("\x08\0\0\0\0", 5);
  return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", header) +
         chunk("IDAT", packed.substr(0, packed.size() / 2)) +
         chunk("IDAT", packed.substr(packed.size() / 2)) + chunk("IEND", "");
}

// Grey PNGs with every filter type load exactly, and as libpng (behind
// cv::imdecode) reads them; a corrupt one is refused with the file's name.
TEST_F(ImageIoTest, GreyPngsWithEveryFilterLoadExactly) {
  cv::Mat image(23, 37, CV_8UC1);
  cv::randu(image, 0, 256);
  image.rowRange(0, 8) = ramp_(cv::Rect(0, 0, 37, 8)) * 1.0;
  int (*filters[])(int) = {[](int) { return 0; }, [](int) { return 1; },
                           [](int) { return 2; }, [](int) { return 3; },
                           [](int) { return 4; }, [](int y) { return y % 5; }};
  for (int k = 0; k < 6; ++k) {
    const std::string name = "filter" + std::to_string(k) + ".png";
    const std::string png = GreyPng(image, filters[k]);
    WriteBytes(name, png);
    cv::Mat grey;
    std::string error;
    ASSERT_TRUE(LoadGreyImage(Path(name), {}, &grey, &error)) << error;
    ASSERT_EQ(grey.size(), image.size()) << name;
    EXPECT_EQ(cv::norm(grey, image, cv::NORM_INF), 0.0) << name;
    const cv::Mat by_libpng =
        cv::imdecode(std::vector<unsigned char>(png.begin(), png.end()),
                     cv::IMREAD_UNCHANGED);
    ASSERT_EQ(by_libpng.size(), image.size()) << name;
    EXPECT_EQ(cv::norm(by_libpng, image, cv::NORM_INF), 0.0) << name;
  }
  std::string corrupt = GreyPng(image, filters[5]);
  corrupt[corrupt.size() - 40] ^= 0x5A;  // inside the second IDAT
  WriteBytes("corrupt.png", corrupt);
  cv::Mat grey;
  std::string error;
  EXPECT_FALSE(LoadGreyImage(Path("corrupt.png"), {}, &grey, &error));
  EXPECT_NE(error.find("corrupt.png"), std::string::npos) << error;
  EXPECT_TRUE(grey.empty());
}

// One loader over a sequence of files (grey PNGs of two sizes, a colour
// PNG, a JPEG, a corrupt file): each image equals what a fresh
// LoadGreyImage gives, a failure leaves the loader usable, and an image the
// caller still holds keeps its pixels when the next file is loaded.
TEST_F(ImageIoTest, LoaderReusedAcrossFilesGivesTheSameImages) {
  cv::Mat noise(40, 60, CV_8UC1), wide(31, 77, CV_8UC1);
  cv::randu(noise, 0, 256);
  cv::randu(wide, 0, 256);
  cv::Mat colour;
  cv::cvtColor(ramp_, colour, cv::COLOR_GRAY2BGR);
  cv::imwrite(Path("0_ramp.png"), ramp_);
  cv::imwrite(Path("1_noise.png"), noise);
  cv::imwrite(Path("2_wide.png"), wide);
  cv::imwrite(Path("3_colour.png"), colour);
  cv::imwrite(Path("4_ramp.jpg"), ramp_);
  WriteBytes("5_corrupt.png", ReadBytes("1_noise.png").substr(0, 60));
  cv::imwrite(Path("6_ramp.png"), ramp_);
  const std::string names[] = {"0_ramp.png",   "1_noise.png", "2_wide.png",
                               "3_colour.png", "4_ramp.jpg",  "5_corrupt.png",
                               "6_ramp.png"};
  ImageLoader loader;
  cv::Mat held, held_copy;
  for (const std::string& name : names) {
    cv::Mat by_loader, fresh;
    std::string loader_error, fresh_error;
    const bool loaded = loader.Load(Path(name), &by_loader, &loader_error);
    ASSERT_EQ(loaded, LoadGreyImage(Path(name), {}, &fresh, &fresh_error))
        << name;
    EXPECT_EQ(loader_error, fresh_error) << name;
    if (!loaded) {
      EXPECT_TRUE(by_loader.empty()) << name;
      EXPECT_NE(loader_error.find(name), std::string::npos) << loader_error;
      continue;
    }
    ASSERT_EQ(by_loader.size(), fresh.size()) << name;
    EXPECT_EQ(cv::norm(by_loader, fresh, cv::NORM_INF), 0.0) << name;
    if (!held.empty()) {
      EXPECT_EQ(cv::norm(held, held_copy, cv::NORM_INF), 0.0)
          << "the image before " << name << " changed";
    }
    held = by_loader;
    held_copy = by_loader.clone();
  }
}

TEST_F(ImageIoTest, RefusesImagesAboveThePixelLimit) {
  cv::imwrite(Path("ramp.png"), ramp_);
  ImageLoadOptions options;
  options.max_pixels = 1000;  // the ramp has 2400
  cv::Mat grey;
  std::string error;
  EXPECT_FALSE(LoadGreyImage(Path("ramp.png"), options, &grey, &error));
  EXPECT_NE(error.find("exceeds"), std::string::npos) << error;
}

}  // namespace
}  // namespace puzzlecal
