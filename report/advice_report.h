#ifndef PUZZLECAL_REPORT_ADVICE_REPORT_H_
#define PUZZLECAL_REPORT_ADVICE_REPORT_H_

// Capture advice (advice/advice.h) as files a person can follow: for each
// advised view a picture of the image frame with the board's outline drawn
// where it should appear (as the camera sees it, distortion included) over
// a faint copy of the corners seen so far, next_1.png, next_2.png, ...;
// advice.yaml with the poses (cam_from_board R, t) and the uncertainty
// expected after each; and a Markdown section for summary.md.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "advice/advice.h"
#include "calib/calibrate.h"
#include "camera/calibration_view.h"

namespace puzzlecal {

// The picture of advised view `index` (0 first), `width` pixels wide
// (0: the image's own size and the margin): the image frame with room
// around it (a board larger than the view shows whole), `seen` (the inlier
// corners of the views taken) as faint dots, the board where it should
// appear (filled, outlined), its centre, and the words.
// CV_8UC3.
cv::Mat DrawAdvicePicture(const Advice& advice, int index,
                          const std::vector<Eigen::Vector2d>& seen, int width);

// The inlier corners of the used views of `result`, in pixels.
std::vector<Eigen::Vector2d> SeenCorners(
    const std::vector<CalibrationView>& views, const CalibrationResult& result);

// advice.yaml: the judged field, the noise, the uncertainty now, each
// advised view (words, cam_from_board R and t, centre, distance, tilt, the
// uncertainty expected after it) and the estimate of photos needed.
std::string AdviceYaml(const Advice& advice);

// File name of advised view `index`'s picture: "next_1.png", ...
std::string AdvicePictureName(int index);

// Writes the pictures (AdvicePictureName) and advice.yaml into `dir`,
// atomically, each `width` pixels wide (0: the image size); appends the
// file names written to `files`. False with a message naming the file.
bool WriteAdviceFiles(const std::string& dir, const Advice& advice,
                      const std::vector<Eigen::Vector2d>& seen, int width,
                      std::vector<std::string>* files, std::string* error);

// The advice as a Markdown section (heading at `heading_level`) that
// embeds the pictures by their file names.
std::string AdviceMarkdown(const Advice& advice, int heading_level);

}  // namespace puzzlecal

#endif  // PUZZLECAL_REPORT_ADVICE_REPORT_H_
