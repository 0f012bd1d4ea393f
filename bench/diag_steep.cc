// scratch: per-corner error and recall of steep candidate views vs truth.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "advice/advice.h"
#include "calib/calibrate.h"
#include "pipeline/pipeline.h"
#include "sim/render.h"
#include "sim/scenes.h"
#include "sim/synthetic_views.h"
#include "util/statistics.h"
#include "detection/corner_filters.h"
#include "detection/subpixel.h"
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

using namespace puzzlecal;

struct Bin { int n = 0, found = 0; double sq = 0; int tail = 0; };

int main(int argc, char** argv) {
  const SceneSpec sample = SampleScene();
  Camera camera = sample.camera;
  Board board = sample.board;
  if (argc > 1 && std::string(argv[1]) == "fisheye") camera = FisheyeLensCamera(640, 480, 180.0);
  RenderOptions render = sample.render;
  render.occluders.clear();
  // start views to get candidates
  const auto start = sim::CentredFrontalPoses(camera, board, 6, 3);
  std::vector<ImageResult> images(start.size());
  PipelineOptions pipeline;
  for (size_t k = 0; k < start.size(); ++k) {
    RenderOptions r = render; r.seed = 100 + k;
    cv::Mat img = RenderBoard(board, camera, start[k], r);
    images[k].file = "s" + std::to_string(k);
    ProcessGreyImage(img, board, pipeline, &images[k]);
  }
  int w, h;
  auto views = MakeCalibrationViews(board, &images, &w, &h);
  CalibrationResult result; std::string error;
  Calibrate(views, camera.model, camera.width, camera.height, CalibrationOptions(), &result, &error);
  const Advice advice = AdviseViews(views, result, board, AdviceOptions());
  std::vector<Eigen::Isometry3d> poses = advice.candidate_poses;
  for (auto& v : advice.views) poses.push_back(v.cam_from_board);
  std::mt19937 rng(3);
  std::shuffle(poses.begin(), poses.end() - advice.views.size(), rng);
  int use = std::min<int>(poses.size(), argc > 2 ? atoi(argv[2]) : 60);
  std::vector<Eigen::Isometry3d> sel(poses.begin(), poses.begin() + use);
  for (auto& v : advice.views) sel.push_back(v.cam_from_board);
  std::map<std::string, Bin> bins;
  std::vector<CalibrationView> views_base, views_rec;
  std::vector<double> all, outer_e, rec_err; int rec_noagree = 0, rec_dup = 0, rec_fail = 0, rec_orient = 0, rec_invisible = 0; std::map<std::string,int> lost; double out_sum = 0, out_sq = 0, tan_sq = 0; int out_n = 0;
  for (size_t k = 0; k < sel.size(); ++k) {
    RenderOptions r = render; r.seed = 500 + k;
    RenderTruth truth;
    cv::Mat img = RenderBoard(board, camera, sel[k], r, &truth);
    if (img.empty()) continue;
    std::vector<std::pair<std::string, std::vector<Corner>>> relaxed;
    {
      auto add = [&](const std::string& name, DetectorOptions o) { DetectorSummary sm; relaxed.push_back({name, DetectCorners(img, o, &sm)}); };
      DetectorOptions o; o.use_ring_test = false; add("noring", o);
      o = DetectorOptions(); o.use_corner_mask = false; add("nomask", o);
      o = DetectorOptions(); o.noise_response_factor = 0; o.min_response = 1e-5; add("nothresh", o);
      o = DetectorOptions(); o.max_shift_fraction = 5; add("noshift", o);
      o = DetectorOptions(); o.nms_radius_px = 1; add("nms1", o);
      o = DetectorOptions(); o.max_ring_asymmetry = 5; o.max_ring_asymmetry_clean = 5; add("asym", o);
      o = DetectorOptions(); o.max_ring_centre_offset=5; add("centre", o);
      o = DetectorOptions(); o.min_ring_second_harmonic=0; o.min_ring_second_harmonic_clean=0; add("harmonic", o);
      o = DetectorOptions(); o.min_ring_contrast=0; o.ring_noise_factor = 0; add("contrast", o);
      o = DetectorOptions(); o.ring_radius_px = 1.5; add("radius1.5", o);
      o = DetectorOptions(); o.ring_radius_px = 2.0; add("radius2", o);
    }
    cv::Mat fimg; img.convertTo(fimg, CV_32F, 1.0 / 255); double mx; cv::minMaxLoc(fimg, nullptr, &mx); fimg /= mx; cv::GaussianBlur(fimg, fimg, cv::Size(5,5), 1.0);
    ImageResult res; res.file = "c";
    ProcessGreyImage(img, board, pipeline, &res);
    std::map<std::pair<int,int>, Eigen::Vector2d> truth_xy;
    for (auto& t : truth.corners) if (t.visible) truth_xy[{t.id.x(), t.id.y()}] = t.xy;
    std::map<std::pair<int,int>, Eigen::Vector2d> found;
    if (res.outcome == ImageOutcome::kUsable)
      for (size_t i = 0; i < res.decode.observation.id.size(); ++i)
        found[{res.decode.observation.id[i].x(), res.decode.observation.id[i].y()}] = res.decode.observation.xy[i];
    std::map<std::pair<int,int>, Eigen::Vector2d> found_before = found;
    // prototype recovery
    if (res.outcome == ImageOutcome::kUsable) {
      std::map<std::pair<int,int>, Eigen::Vector2d> have = found;
      for (int round = 0; round < 2; ++round) {
      std::map<std::pair<int,int>, Eigen::Vector2d> add;
      for (int y = board.origin.y(); y < board.origin.y() + board.rows; ++y)
      for (int x = board.origin.x(); x < board.origin.x() + board.cols; ++x) {
        if (have.count({x,y})) continue;
        std::vector<std::pair<Eigen::Vector2d,double>> preds;
        auto get = [&](int dx, int dy, Eigen::Vector2d* p) { auto it = have.find({x+dx, y+dy}); if (it == have.end()) return false; *p = it->second; return true; };
        const int dirs[4][2] = {{1,0},{-1,0},{0,1},{0,-1}};
        for (auto& d : dirs) { Eigen::Vector2d p1,p2,p3; if (get(d[0],d[1],&p1) && get(2*d[0],2*d[1],&p2) && get(3*d[0],3*d[1],&p3)) preds.push_back({3*p1-3*p2+p3, (p1-p2).norm()}); }
        for (int ax = 0; ax < 2; ++ax) { int ux = ax==0, uy = ax==1; Eigen::Vector2d m1,p1,m2,p2; if (get(-ux,-uy,&m1) && get(ux,uy,&p1)) { if (get(-2*ux,-2*uy,&m2) && get(2*ux,2*uy,&p2)) preds.push_back({(-m2+4*m1+4*p1-p2)/6, 0.5*(p1-m1).norm()}); else preds.push_back({0.5*(m1+p1), 0.5*(p1-m1).norm()}); } }
        for (int sx : {-1,1}) for (int sy : {-1,1}) { Eigen::Vector2d a1,a2,a3; if (get(sx,0,&a1) && get(0,sy,&a2) && get(sx,sy,&a3)) preds.push_back({a1+a2-a3, std::min((a1-a3).norm(), (a2-a3).norm())}); }
        if (preds.size() < 2) continue;
        int bestc = 0; Eigen::Vector2d pred; double spacing = 0;
        for (auto& q : preds) { int c = 0; Eigen::Vector2d sum = Eigen::Vector2d::Zero(); double sp = 0; for (auto& r2 : preds) if ((r2.first - q.first).norm() < 0.15 * q.second) { ++c; sum += r2.first; sp += r2.second; } if (c > bestc) { bestc = c; pred = sum / c; spacing = sp / c; } }
        if (bestc < 2 || 2 * bestc <= (int)preds.size()) { rec_noagree++; continue; }
        auto proj = [&](double u, double v) { Eigen::Vector2d p; if (get((int)u,(int)v,&p)) return p; return Eigen::Vector2d(pred); };
        std::vector<int> src(bestc);
        double sigma = std::clamp(0.1 * spacing, 1.0, 6.0);
        SaddleRefineResult r = RefineBySaddleFit(img, pred, sigma, 4, 0.05, 0.25 * spacing);
        if (!r.ok || r.iterations >= 4) { rec_fail++; continue; }
        // expected bright diagonal
        Eigen::Vector2d ex = Eigen::Vector2d::Zero(), ey = Eigen::Vector2d::Zero(); { Eigen::Vector2d p1, p2; if (get(1,0,&p1)) ex = p1 - pred; else if (get(-1,0,&p2)) ex = pred - p2; if (get(0,1,&p1)) ey = p1 - pred; else if (get(0,-1,&p2)) ey = pred - p2; }
        if (ex.norm() == 0 || ey.norm() == 0) { rec_orient++; continue; }
        Eigen::Vector2d diag = ((x + y) % 2 == 0) ? Eigen::Vector2d(ex.normalized() - ey.normalized()) : Eigen::Vector2d(ex.normalized() + ey.normalized());
        double ang = std::atan2(diag.y(), diag.x());
        double dang = std::remainder(r.orientation - ang, M_PI);
        if (std::abs(dang) > 0.5) { rec_orient++; continue; }
        bool dup = false;
        for (auto& [hid, hxy] : have) if ((hxy - r.xy).norm() < 0.5 * spacing) dup = true;
        if (dup) { rec_dup++; continue; }
        if ((r.xy - pred).norm() > 0.5 * sigma + 0.1 * spacing && false) continue;
        add[{x,y}] = r.xy;
        { auto t = truth_xy.find({x,y}); if (t != truth_xy.end() && (r.xy - t->second).norm() > 1 && argc > 3) std::printf("BADDETAIL view %zu id %d %d pred_err %.2f spacing %.1f sigma %.1f refined_err %.2f iters %d at %.0f %.0f npts %zu\n", k, x, y, (pred - t->second).norm(), spacing, sigma, (r.xy - t->second).norm(), r.iterations, t->second.x(), t->second.y(), src.size()); }
        if (k == 39 && x == 72 && y == 105) { cv::imwrite("/tmp/diag/v39.png", img); }
      }
      for (auto& [id, xy] : add) {
        have[id] = xy;
        auto t = truth_xy.find(id);
        if (t == truth_xy.end()) { rec_invisible++; continue; }
        double e = (xy - t->second).norm(); if (e > 1 && argc > 3) std::printf("BADREC view %zu id %d %d err %.2f\n", k, id.first, id.second, e);
        rec_err.push_back(e);
        found[id] = xy;
      }
      }
    }
    if (found_before.size() >= 20) {
      CalibrationView a, b; a.name = b.name = "v" + std::to_string(k);
      for (auto& [id, xy] : found_before) { a.board_points.push_back(board.Point({id.first, id.second})); a.image_points.push_back(xy); }
      for (auto& [id, xy] : found) { b.board_points.push_back(board.Point({id.first, id.second})); b.image_points.push_back(xy); }
      views_base.push_back(a); views_rec.push_back(b);
    }
    // tilt
    Eigen::Vector3d n = sel[k].linear().col(2);
    double tilt = std::acos(std::abs(n.z())) * 180 / M_PI;
    int ff = 0, nn = 0;
    for (auto& [id, xy] : truth_xy) {
      // local side: min distance to 4-neighbours in truth
      double side = 1e9;
      const int d[4][2] = {{1,0},{-1,0},{0,1},{0,-1}};
      int nb = 0;
      for (auto& dd : d) {
        auto it = truth_xy.find({id.first + dd[0], id.second + dd[1]});
        if (it != truth_xy.end()) { side = std::min(side, (it->second - xy).norm()); ++nb; }
      }
      bool outer = id.first == board.origin.x() || id.second == board.origin.y() ||
                   id.first == board.origin.x() + board.cols - 1 || id.second == board.origin.y() + board.rows - 1;
      double border = std::min({xy.x(), xy.y(), w - 1 - xy.x(), h - 1 - xy.y()});
      std::string sb = side < 4 ? "side<4" : side < 6 ? "side4-6" : side < 9 ? "side6-9" : side < 14 ? "side9-14" : "side>=14";
      std::string bb = border < 10 ? "border<10" : border < 30 ? "border10-30" : "border>=30";
      std::string ob = outer ? "outer" : "inner";
      std::string tb = tilt < 30 ? "tilt<30" : tilt < 45 ? "tilt30-45" : tilt < 60 ? "tilt45-60" : "tilt>=60";
      auto it = found.find(id);
      double e = -1;
      if (it != found.end()) { e = (it->second - xy).norm(); all.push_back(e); ++ff; }
      ++nn;
      if (e < 0) {
        // where lost: detector, grid or decode
        int ci = -1; double best = 1.5;
        for (size_t c = 0; c < res.corners.size(); ++c) { double dd2 = (res.corners[c].xy - xy).norm(); if (dd2 < best) { best = dd2; ci = c; } }
        std::string stage = "detector";
        if (ci < 0) for (auto& [rn, rc] : relaxed) { for (auto& c : rc) if ((c.xy - xy).norm() < 1.5) { lost[std::string(outer ? "outer" : "inner") + " recovered by " + rn]++; break; } }
        if (ci >= 0) { stage = "grid"; for (auto& comp : res.components) for (int cc : comp.corner) if (cc == ci) stage = "decode"; }
        if (outer && ci < 0 && argc > 4) { RingMeasure m = MeasureRing(fimg, xy.x(), xy.y(), 2.5, 16); std::printf("LOSTRING side %.1f asym %.2f share %.2f contrast %.3f centre %.2f tilt %.0f\n", side, m.asymmetry, m.second_harmonic_share, m.contrast, m.centre_offset, tilt); }
        lost[(outer ? "outer/" : "inner/") + stage + (border < 30 ? "/nearborder" : "")]++;
      }
      for (const std::string& key : {sb, bb, ob, tb, std::string("all"), ob+"/"+sb, ob+"/"+tb}) {
        Bin& b = bins[key]; ++b.n;
        if (e >= 0) { ++b.found; b.sq += e * e; if (e > 0.3) ++b.tail; }
      }
      if (outer && e >= 0 && argc > 4 && (nn % 10 == 0)) { RingMeasure m = MeasureRing(fimg, xy.x(), xy.y(), 2.5, 16); std::printf("FOUNDRING side %.1f asym %.2f share %.2f contrast %.3f centre %.2f\n", side, m.asymmetry, m.second_harmonic_share, m.contrast, m.centre_offset); }
      if (outer && e >= 0 && side < 9) {
        // outward: truth corner minus the mean of its in-board neighbours
        Eigen::Vector2d inward = Eigen::Vector2d::Zero();
        for (auto& dd : d) {
          auto jt = truth_xy.find({id.first + dd[0], id.second + dd[1]});
          if (jt != truth_xy.end()) inward += jt->second - xy;
        }
        Eigen::Vector2d err = it->second - xy; outer_e.push_back(e);
        if (inward.norm() > 0) { out_sum += err.dot(-inward.normalized()); ++out_n; out_sq += std::pow(err.dot(-inward.normalized()),2); }
        // tangential: perpendicular
        if (inward.norm() > 0) { Eigen::Vector2d t(-inward.y(), inward.x()); tan_sq += std::pow(err.dot(t.normalized()),2);}
      }
      if (e > 0.5 && argc > 3) std::printf("TAIL view %zu id %d,%d err %.2f side %.1f border %.0f outer %d tilt %.0f nb %d\n", k, id.first, id.second, e, side, border, outer, tilt, nb);
    }
    if (argc > 3) std::printf("view %zu tilt %.0f dist %.2f found %d/%d outcome %s\n", k, tilt, sel[k].translation().norm(), ff, nn, ImageOutcomeName(res.outcome));
  }
  for (auto& [k, b] : bins) std::printf("%-12s n %6d recall %.3f rms %.3f tail>0.3 %.4f\n", k.c_str(), b.n, double(b.found)/b.n, std::sqrt(b.sq/std::max(1,b.found)), double(b.tail)/std::max(1,b.found));
  std::printf("outer small: n %d mean outward %.3f rms outward %.3f rms tangential %.3f\n", out_n, out_sum/out_n, std::sqrt(out_sq/out_n), std::sqrt(tan_sq/out_n));
  std::sort(rec_err.begin(), rec_err.end()); if (!rec_err.empty()) std::printf("noagree %d dup %d ", rec_noagree, rec_dup); std::printf("recovered %zu fail %d orient %d invisible %d p50 %.3f p90 %.3f p99 %.3f max %.3f\n", rec_err.size(), rec_fail, rec_orient, rec_invisible, rec_err[rec_err.size()/2], rec_err[rec_err.size()*9/10], rec_err[rec_err.size()*99/100], rec_err.back());
  for (int which = 0; which < 2; ++which) {
    CalibrationResult cr; std::string err;
    auto& vv = which ? views_rec : views_base;
    if (!Calibrate(vv, camera.model, camera.width, camera.height, CalibrationOptions(), &cr, &err)) { printf("calib fail %s\n", err.c_str()); continue; }
    std::vector<double> te;
    for (int y = 0; y < h; y += 10) for (int x = 0; x < w; x += 10) {
      Eigen::Vector3d ray; if (!camera.Unproject(Eigen::Vector2d(x, y), &ray).converged) continue;
      Eigen::Vector2d p; if (!cr.camera.Project(ray, &p)) continue;
      te.push_back((p - Eigen::Vector2d(x, y)).norm());
    }
    std::sort(te.begin(), te.end());
    printf("%s: views %zu corners %d rms %.4f stated_noise %.4f truth err median %.4f p90 %.4f max %.4f\n", which ? "recovered" : "base", vv.size(), cr.num_corners_used, cr.rms_px, StatedNoiseSigma(cr), te[te.size()/2], te[te.size()*9/10], te.back());
  }
  for (auto& [k2, v] : lost) std::printf("lost %s %d\n", k2.c_str(), v);
  std::sort(outer_e.begin(), outer_e.end()); {auto& a = outer_e; std::printf("outer small p50 %.3f p75 %.3f p90 %.3f p95 %.3f p99 %.3f\n", a[a.size()/2], a[a.size()*3/4], a[a.size()*9/10], a[a.size()*95/100], a[a.size()*99/100]);}
  std::sort(all.begin(), all.end());
  if (!all.empty()) std::printf("p50 %.3f p90 %.3f p99 %.3f max %.3f\n", all[all.size()/2], all[all.size()*9/10], all[all.size()*99/100], all.back());
}
