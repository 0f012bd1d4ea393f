#include "report/html.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/support/files.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

// Keeps an image's src as it is.
std::string SameSrc(const std::string& src) { return src; }

TEST(HtmlTest, DataUriEncodesTheRfc4648Vectors) {
  // RFC 4648, section 10.
  const std::string prefix = "data:image/png;base64,";
  EXPECT_EQ(DataUri("image/png", ""), prefix);
  EXPECT_EQ(DataUri("image/png", "f"), prefix + "Zg==");
  EXPECT_EQ(DataUri("image/png", "fo"), prefix + "Zm8=");
  EXPECT_EQ(DataUri("image/png", "foo"), prefix + "Zm9v");
  EXPECT_EQ(DataUri("image/png", "foob"), prefix + "Zm9vYg==");
  EXPECT_EQ(DataUri("image/png", "fooba"), prefix + "Zm9vYmE=");
  EXPECT_EQ(DataUri("image/png", "foobar"), prefix + "Zm9vYmFy");
  // Bytes above 127 are unsigned.
  EXPECT_EQ(DataUri("x", std::string("\xff\xfe", 2)), "data:x;base64,//4=");
}

TEST(HtmlTest, ConvertsTheSubsetTheReportsWrite) {
  const std::string markdown =
      "# Calibration report\n\n"
      "**verdict: good — RMS 0.1 px** and `code <x>`\n"
      "continued line.\n\n"
      "## Worst views\n\n"
      "| # | image | RMS (px) |\n"
      "|---:|---|---:|\n"
      "| 4 | a\\|b.png | 0.250 |\n\n"
      "- `residuals.png`: arrows\n\n"
      "  ![residuals.png](residuals.png)\n\n"
      "- second & last\n\n"
      "```\nfit <model> & more\n```\n\n"
      "### view_rms.png\n\n![view rms](view_rms.png)\n";
  const std::string html = MarkdownToHtml(markdown, "T & U", SameSrc);
  EXPECT_NE(html.find("<title>T &amp; U</title>"), std::string::npos);
  EXPECT_NE(html.find("<h1>Calibration report</h1>"), std::string::npos);
  EXPECT_NE(html.find("<p><strong>verdict: good — RMS 0.1 px</strong> and "
                      "<code>code &lt;x&gt;</code> continued line.</p>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<h2>Worst views</h2>"), std::string::npos);
  EXPECT_NE(html.find("<th style=\"text-align:right\">#</th><th>image</th>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<td style=\"text-align:right\">4</td><td>a|b.png</td>"
                      "<td style=\"text-align:right\">0.250</td>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<li><code>residuals.png</code>: arrows<br><img "
                      "src=\"residuals.png\" alt=\"residuals.png\"></li>\n"
                      "<li>second &amp; last</li>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<pre><code>fit &lt;model&gt; &amp; more\n</code></pre>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<h3>view_rms.png</h3>\n<p><img src=\"view_rms.png\" "
                      "alt=\"view rms\"></p>"),
            std::string::npos)
      << html;
  // One list, one table.
  EXPECT_EQ(html.find("<ul>"), html.rfind("<ul>"));
  EXPECT_EQ(html.find("<table>"), html.rfind("<table>"));
}

TEST(HtmlTest, AnImageWithoutASourceKeepsItsAltText) {
  const std::string html =
      MarkdownToHtml("![the chart](gone.png)\n", "t",
                     [](const std::string&) { return std::string(); });
  EXPECT_EQ(html.find("<img"), std::string::npos);
  EXPECT_NE(html.find("<p>the chart</p>"), std::string::npos) << html;
}

TEST(HtmlTest, AMissingPictureIsNamed) {
  const fs::path dir =
      fs::temp_directory_path() / "puzzlecal_html_test_missing_picture";
  fs::remove_all(dir);
  fs::create_directories(dir);
  testing_files::WriteFile(dir / "summary.md", "# R\n\n![chart](chart.png)\n");
  std::string error;
  EXPECT_FALSE(WriteHtmlReport(dir.string(), "R", &error));
  EXPECT_NE(error.find((dir / "chart.png").string()), std::string::npos)
      << error;
  EXPECT_FALSE(fs::exists(dir / "index.html"));
  fs::remove(dir / "summary.md");
  EXPECT_FALSE(WriteHtmlReport(dir.string(), "R", &error));
  EXPECT_NE(error.find("summary.md"), std::string::npos) << error;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace puzzlecal
