#pragma once
// Command-line spellings of the library's options: parsers for the text forms, and the flag that
// names each option in errors. Ranges are the library's (validateOptions); these check syntax.
#include <string>

#include "pvr/pipeline/frame_options.h"

namespace pvr {

// "separate" | "scatter" | "gather"; throws pvr::Error naming `flag` otherwise.
StereoMode parseStereoMode(const std::string& text, const std::string& flag = "--stereo");

// Sets the rig's per-eye resolution from "WxH"; throws pvr::Error naming --eye-size if it is
// not that form or out of the library's range.
void setEyeSize(StereoRig& rig, const std::string& text);

// The command-line flag of a render option ("--radius").
const char* flagOf(RenderOption option);

// An OptionError's message in the command line's words: "--radius: the search radius must be ...".
std::string describeForCli(const OptionError& error);

}  // namespace pvr
