// Escaping for text that leaves rdyn in another language (issue #9): everything that comes
// from a scene, a file name or the command line goes through one of these.
#pragma once

#include <string>

namespace rdyn::validate {

// HTML text and attribute values: & < > " ' as character references.
std::string html_escape(const std::string& text);

// A gnuplot single-quoted string literal, quotes included ('' stands for ').
std::string gnuplot_quoted(const std::string& text);

// A CSV field per RFC 4180: quoted when it holds a comma, a quote, CR or LF (quotes doubled).
std::string csv_field(const std::string& text);

// Base64 (RFC 4648, with padding): an SVG as a data: URI in an <img>, which runs no script.
std::string base64(const std::string& bytes);

}  // namespace rdyn::validate
