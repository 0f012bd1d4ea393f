// The report as one self-contained web page: index.html beside summary.md,
// for readers without a Markdown viewer, with every plot inline.

#ifndef PUZZLECAL_REPORT_HTML_H_
#define PUZZLECAL_REPORT_HTML_H_

#include <functional>
#include <string>

namespace puzzlecal {

// The data: URI of a file's bytes ("data:image/png;base64,...").
std::string DataUri(const std::string& mime_type, const std::string& bytes);

// An HTML page of `markdown` in the subset the reports write: ATX headings
// (#, ##, ###), paragraphs, pipe tables (a header row, a |---| row, body
// rows), "- " lists, ``` fenced blocks, and inline `code`, **bold**,
// images ![alt](src) and links [text](href). Text is HTML-escaped.
// `image_src` maps an image's src to what the page uses (a data: URI, or
// the src itself); an empty answer drops the image and keeps its alt text.
std::string MarkdownToHtml(
    const std::string& markdown, const std::string& title,
    const std::function<std::string(const std::string&)>& image_src);

// Writes DIR/index.html from DIR/summary.md (already written): every image
// the summary names that lies in DIR is read and inlined as a data: URI,
// so the page is one file. Atomic (util/atomic_file.h). False with a
// message naming the file when summary.md or an image cannot be read or
// the page cannot be written.
bool WriteHtmlReport(const std::string& dir, const std::string& title,
                     std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_REPORT_HTML_H_
