#include "layout_fixtures.hpp"

#include "neuflow/flow/flow_io.hpp"

namespace neuflow::eval::test {

namespace fs = std::filesystem;

void link_file(const fs::path& target, const fs::path& link) {
  fs::create_directories(link.parent_path());
  fs::create_symlink(target, link);
}

fs::path arrange_sintel(const fs::path& flow_gt, const fs::path& root) {
  struct Scene {
    const char* fixture;
    const char* scene;
    const char* frame0;
    const char* frame1;
  };
  for (const Scene& s : {Scene{"alley_1_clean_0002", "alley_1", "frame_0002", "frame_0003"},
                         Scene{"market_5_final_0009", "market_5", "frame_0009", "frame_0010"}}) {
    const fs::path src = flow_gt / "sintel" / s.fixture;
    link_file(src / "flow.flo", root / "training/flow" / s.scene / (std::string(s.frame0) + ".flo"));
    // The fixtures hold one pass per pair; both passes get its images, which is all a layout
    // needs.
    for (const char* pass : {"clean", "final"}) {
      link_file(src / "frame1.png", root / "training" / pass / s.scene / (std::string(s.frame0) + ".png"));
      link_file(src / "frame2.png", root / "training" / pass / s.scene / (std::string(s.frame1) + ".png"));
    }
  }
  return root;
}

fs::path arrange_kitti(const fs::path& flow_gt, const fs::path& root) {
  link_file(flow_gt / "kitti/frame1.png", root / "training/image_2/000000_10.png");
  link_file(flow_gt / "kitti/frame2.png", root / "training/image_2/000000_11.png");
  link_file(flow_gt / "kitti/flow_gt.png", root / "training/flow_occ/000000_10.png");
  return root;
}

fs::path arrange_middlebury(const fs::path& flow_gt, const fs::path& root) {
  for (const char* seq : {"RubberWhale", "Urban2"}) {
    link_file(flow_gt / "middlebury" / seq / "frame10.png", root / "other-data" / seq / "frame10.png");
    link_file(flow_gt / "middlebury" / seq / "frame11.png", root / "other-data" / seq / "frame11.png");
    link_file(flow_gt / "middlebury" / seq / "flow10.flo", root / "other-gt-flow" / seq / "flow10.flo");
  }
  return root;
}

fs::path arrange_chairs(const fs::path& flow_gt, const fs::path& root) {
  for (const char* id : {"00001", "00002"}) {
    link_file(flow_gt / "flyingchairs/0000000-img0.ppm", root / "data" / (std::string(id) + "_img1.ppm"));
    link_file(flow_gt / "flyingchairs/0000000-img1.ppm", root / "data" / (std::string(id) + "_img2.ppm"));
    link_file(flow_gt / "flyingchairs/0000000-gt.flo", root / "data" / (std::string(id) + "_flow.flo"));
  }
  return root;
}

void write_predictions(const EvalSet& set, const fs::path& dir, const std::string& extension,
                       const std::function<void(flow::FlowField&)>& transform) {
  for (const Pair& pair : set.pairs) {
    flow::FlowField field = flow::read_flow(pair.ground_truth);
    transform(field);
    const fs::path out = dir / (pair.key + extension);
    fs::create_directories(out.parent_path());
    flow::write_flow(field, out);
  }
}

std::function<void(flow::FlowField&)> offset_by(float du, float dv) {
  return [du, dv](flow::FlowField& f) {
    for (std::size_t i = 0; i < f.pixel_count(); ++i) {
      f.uv[2 * i] += du;
      f.uv[2 * i + 1] += dv;
    }
  };
}

}  // namespace neuflow::eval::test
