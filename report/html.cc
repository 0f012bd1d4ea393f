#include "report/html.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

#include "util/atomic_file.h"
#include "util/failure.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

std::string Escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

bool StartsWith(const std::string& text, const std::string& prefix) {
  return text.compare(0, prefix.size(), prefix) == 0;
}

// "[text](target)" starting at text[at] == '['; false when it is not one.
bool ParseBracketLink(const std::string& text, size_t at, std::string* label,
                      std::string* target, size_t* end) {
  const size_t close = text.find("](", at);
  if (close == std::string::npos) return false;
  const size_t paren = text.find(')', close + 2);
  if (paren == std::string::npos) return false;
  *label = text.substr(at + 1, close - at - 1);
  *target = text.substr(close + 2, paren - close - 2);
  *end = paren + 1;
  return true;
}

// Inline markup of one paragraph, heading or cell.
std::string Inline(
    const std::string& text,
    const std::function<std::string(const std::string&)>& image_src) {
  std::string out;
  bool bold = false;
  for (size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (c == '\\' && i + 1 < text.size() &&
        std::string("\\`*_[]()|#!-").find(text[i + 1]) != std::string::npos) {
      out += Escape(std::string(1, text[i + 1]));
      i += 2;
    } else if (c == '`') {
      const size_t close = text.find('`', i + 1);
      if (close == std::string::npos) {
        out += "`";
        ++i;
        continue;
      }
      out += "<code>" + Escape(text.substr(i + 1, close - i - 1)) + "</code>";
      i = close + 1;
    } else if (text.compare(i, 2, "**") == 0) {
      out += bold ? "</strong>" : "<strong>";
      bold = !bold;
      i += 2;
    } else if (text.compare(i, 2, "![") == 0) {
      std::string alt, src;
      size_t end = 0;
      if (!ParseBracketLink(text, i + 1, &alt, &src, &end)) {
        out += "!";
        ++i;
        continue;
      }
      const std::string use = image_src(src);
      if (use.empty()) {
        out += Escape(alt);
      } else {
        out += "<img src=\"" + Escape(use) + "\" alt=\"" + Escape(alt) + "\">";
      }
      i = end;
    } else if (c == '[') {
      std::string label, href;
      size_t end = 0;
      if (!ParseBracketLink(text, i, &label, &href, &end)) {
        out += "[";
        ++i;
        continue;
      }
      out += "<a href=\"" + Escape(href) + "\">" + Inline(label, image_src) +
             "</a>";
      i = end;
    } else {
      out += Escape(std::string(1, c));
      ++i;
    }
  }
  if (bold) out += "</strong>";
  return out;
}

std::string Trim(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  const size_t last = text.find_last_not_of(" \t\r");
  return text.substr(first, last - first + 1);
}

// The cells of a pipe-table row ("| a | b |"); "\|" stays in its cell.
std::vector<std::string> Cells(const std::string& row) {
  std::string line = Trim(row);
  if (StartsWith(line, "|")) line.erase(0, 1);
  if (!line.empty() && line.back() == '|' &&
      (line.size() < 2 || line[line.size() - 2] != '\\')) {
    line.pop_back();
  }
  std::vector<std::string> cells(1);
  for (size_t i = 0; i < line.size(); ++i) {
    if (line[i] == '\\' && i + 1 < line.size() && line[i + 1] == '|') {
      cells.back() += "\\|";
      ++i;
    } else if (line[i] == '|') {
      cells.emplace_back();
    } else {
      cells.back() += line[i];
    }
  }
  for (std::string& cell : cells) cell = Trim(cell);
  return cells;
}

bool IsSeparatorRow(const std::string& row) {
  const std::string line = Trim(row);
  return !line.empty() && line[0] == '|' &&
         line.find_first_not_of("|-: ") == std::string::npos &&
         line.find('-') != std::string::npos;
}

// The alignment attribute of a column from its separator cell.
std::string Align(const std::string& separator_cell) {
  const bool left = StartsWith(separator_cell, ":");
  const bool right = !separator_cell.empty() && separator_cell.back() == ':';
  if (left && right) return " style=\"text-align:center\"";
  if (right) return " style=\"text-align:right\"";
  return "";
}

constexpr char kStyle[] =
    "body{font-family:sans-serif;max-width:70em;margin:1em auto;"
    "padding:0 1em;line-height:1.45;color:#222}"
    "table{border-collapse:collapse;margin:0.5em 0}"
    "th,td{border:1px solid #ccc;padding:0.2em 0.5em;vertical-align:top}"
    "th{background:#f2f2f2}"
    "code{background:#f4f4f4;padding:0 0.2em}"
    "pre{background:#f4f4f4;padding:0.6em;overflow-x:auto}"
    "img{max-width:100%;height:auto;display:block;margin:0.4em 0}";

}  // namespace

std::string DataUri(const std::string& mime_type, const std::string& bytes) {
  static const char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out = "data:" + mime_type + ";base64,";
  out.reserve(out.size() + (bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = static_cast<uint8_t>(bytes[i]) << 16 |
                       static_cast<uint8_t>(bytes[i + 1]) << 8 |
                       static_cast<uint8_t>(bytes[i + 2]);
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const uint32_t v = static_cast<uint8_t>(bytes[i]) << 16 |
                       (two ? static_cast<uint8_t>(bytes[i + 1]) << 8 : 0);
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += two ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string MarkdownToHtml(
    const std::string& markdown, const std::string& title,
    const std::function<std::string(const std::string&)>& image_src) {
  std::vector<std::string> lines;
  {
    std::istringstream in(markdown);
    for (std::string line; std::getline(in, line);) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      lines.push_back(line);
    }
  }
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta "
          "charset=\"utf-8\">\n<title>"
       << Escape(title) << "</title>\n<style>" << kStyle
       << "</style>\n</head>\n<body>\n";
  auto inline_text = [&](const std::string& text) {
    return Inline(text, image_src);
  };
  std::string paragraph;
  auto end_paragraph = [&] {
    if (!paragraph.empty()) html << "<p>" << inline_text(paragraph) << "</p>\n";
    paragraph.clear();
  };
  for (size_t i = 0; i < lines.size();) {
    const std::string& line = lines[i];
    const std::string trimmed = Trim(line);
    if (StartsWith(trimmed, "```")) {
      end_paragraph();
      html << "<pre><code>";
      for (++i; i < lines.size() && !StartsWith(Trim(lines[i]), "```"); ++i) {
        html << Escape(lines[i]) << "\n";
      }
      html << "</code></pre>\n";
      ++i;  // the closing fence
      continue;
    }
    if (trimmed.empty()) {
      end_paragraph();
      ++i;
      continue;
    }
    size_t level = 0;
    while (level < trimmed.size() && trimmed[level] == '#') ++level;
    if (level >= 1 && level <= 6 && level < trimmed.size() &&
        trimmed[level] == ' ') {
      end_paragraph();
      html << "<h" << level << ">" << inline_text(Trim(trimmed.substr(level)))
           << "</h" << level << ">\n";
      ++i;
      continue;
    }
    if (StartsWith(trimmed, "|") && i + 1 < lines.size() &&
        IsSeparatorRow(lines[i + 1])) {
      end_paragraph();
      const std::vector<std::string> header = Cells(line);
      const std::vector<std::string> separator = Cells(lines[i + 1]);
      auto align = [&](size_t c) {
        return c < separator.size() ? Align(separator[c]) : std::string();
      };
      html << "<table>\n<thead><tr>";
      for (size_t c = 0; c < header.size(); ++c) {
        html << "<th" << align(c) << ">" << inline_text(header[c]) << "</th>";
      }
      html << "</tr></thead>\n<tbody>\n";
      for (i += 2; i < lines.size() && StartsWith(Trim(lines[i]), "|"); ++i) {
        const std::vector<std::string> cells = Cells(lines[i]);
        html << "<tr>";
        for (size_t c = 0; c < cells.size(); ++c) {
          html << "<td" << align(c) << ">" << inline_text(cells[c]) << "</td>";
        }
        html << "</tr>\n";
      }
      html << "</tbody>\n</table>\n";
      continue;
    }
    if (StartsWith(line, "- ")) {
      end_paragraph();
      html << "<ul>\n";
      while (i < lines.size() && StartsWith(lines[i], "- ")) {
        std::string item = lines[i].substr(2);
        // Continuation lines, and indented paragraphs after blank lines.
        for (++i; i < lines.size(); ++i) {
          if (StartsWith(lines[i], "  ") && !Trim(lines[i]).empty()) {
            item += " " + Trim(lines[i]);
            continue;
          }
          size_t next = i;
          while (next < lines.size() && Trim(lines[next]).empty()) ++next;
          if (next > i && next < lines.size() &&
              StartsWith(lines[next], "  ")) {
            item += "\n";  // a paragraph break inside the item
            i = next - 1;
            continue;
          }
          break;
        }
        html << "<li>";
        std::istringstream parts(item);
        bool first = true;
        for (std::string part; std::getline(parts, part); first = false) {
          html << (first ? "" : "<br>") << inline_text(Trim(part));
        }
        html << "</li>\n";
        while (i < lines.size() && Trim(lines[i]).empty() &&
               i + 1 < lines.size() && StartsWith(lines[i + 1], "- ")) {
          ++i;  // a blank line between items keeps the list
        }
      }
      html << "</ul>\n";
      continue;
    }
    paragraph += (paragraph.empty() ? "" : " ") + trimmed;
    ++i;
  }
  end_paragraph();
  html << "</body>\n</html>\n";
  return html.str();
}

bool WriteHtmlReport(const std::string& dir, const std::string& title,
                     std::string* error) {
  const fs::path folder(dir);
  auto read = [&](const fs::path& path, std::string* bytes) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    bytes->assign(std::istreambuf_iterator<char>(in),
                  std::istreambuf_iterator<char>());
    return !in.bad();
  };
  std::string markdown;
  if (!read(folder / "summary.md", &markdown)) {
    return Fail("cannot read " + (folder / "summary.md").string() +
                    " to write the web page beside it",
                error);
  }
  std::string missing;
  auto image_src = [&](const std::string& src) -> std::string {
    // Only plain file names of the folder are inlined.
    if (src.find('/') != std::string::npos ||
        src.find("..") != std::string::npos) {
      return src;
    }
    std::string bytes;
    if (!read(folder / src, &bytes)) {
      if (missing.empty()) missing = (folder / src).string();
      return "";
    }
    const std::string extension = fs::path(src).extension().string();
    return DataUri(extension == ".svg" ? "image/svg+xml" : "image/png", bytes);
  };
  const std::string page = MarkdownToHtml(markdown, title, image_src);
  if (!missing.empty()) {
    return Fail("cannot read " + missing + " to put it into index.html", error);
  }
  return WriteFileAtomically((folder / "index.html").string(), page, error);
}

}  // namespace puzzlecal
