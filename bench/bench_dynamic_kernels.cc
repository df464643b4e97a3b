// Kernels of the Det-SLAM stage that run on every frame (Google Benchmark, single thread): mask
// dilation by the elliptic kernel (DilateEllipse against cv::dilate, on a person-sized mask and on
// a full-frame mask as the mask propagation grows it), carrying masks to the next frames
// (MaskCarrier: optical flow + growth), and the regions a frame's masks become before its ORB
// extraction (dilated masks, the depth step's interval, the ignore mask). Synthetic 640x480
// images; no data needed.
#include <benchmark/benchmark.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "detslam/dynamic/dynamic_filter.h"
#include "detslam/dynamic/ellipse_dilate.h"
#include "detslam/dynamic/mask_carrier.h"
#include "kernel_bench_main.h"

namespace {

// A person-like blob (ellipse body + circle head) in a 640x480 mask.
cv::Mat PersonMask(int dx = 0) {
  cv::Mat mask = cv::Mat::zeros(480, 640, CV_8UC1);
  cv::ellipse(mask, {300 + dx, 300}, {70, 160}, 0, 0, 360, cv::Scalar(255), cv::FILLED);
  cv::circle(mask, {300 + dx, 120}, 40, cv::Scalar(255), cv::FILLED);
  return mask;
}

// Textured 640x480 grey image with the person (its own texture, moved with it) shifted by dx.
cv::Mat Frame(int dx) {
  cv::Mat background(480, 640, CV_8UC1), person(480, 640, CV_8UC1);
  cv::RNG(3).fill(background, cv::RNG::UNIFORM, 0, 120);
  cv::RNG(4).fill(person, cv::RNG::UNIFORM, 120, 255);
  cv::GaussianBlur(background, background, cv::Size(5, 5), 0);
  cv::GaussianBlur(person, person, cv::Size(5, 5), 0);
  cv::Mat moved;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, 0);
  cv::warpAffine(person, moved, shift, person.size());
  moved.copyTo(background, PersonMask(dx));
  return background;
}

void BM_DilateOpenCvEllipse(benchmark::State& state) {
  cv::setNumThreads(1);
  const int r = static_cast<int>(state.range(0));
  const cv::Mat mask = PersonMask();
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1));
  cv::Mat out;
  for (auto _ : state) {
    cv::dilate(mask, out, kernel);
    benchmark::DoNotOptimize(out.data);
  }
}
BENCHMARK(BM_DilateOpenCvEllipse)->Arg(6)->Arg(15)->Arg(24)->Unit(benchmark::kMillisecond);

void BM_DilateEllipse(benchmark::State& state) {
  cv::setNumThreads(1);
  const int r = static_cast<int>(state.range(0));
  const cv::Mat mask = PersonMask();
  for (auto _ : state) {
    cv::Mat out = detslam::DilateEllipse(mask, r);
    benchmark::DoNotOptimize(out.data);
  }
}
BENCHMARK(BM_DilateEllipse)->Arg(6)->Arg(15)->Arg(24)->Unit(benchmark::kMillisecond);

// Carrying masks frame after frame as the camera-rate pipeline does: a new segmentation (of two
// people) is published every `age` frames (its publishing, the segmentation thread's, is not
// timed); each iteration carries the newest one to the next frame (the people move 4 px a frame).
// Arguments: frames per segmentation, MaskPropagationOptions::flow_scale.
void BM_MaskCarry(benchmark::State& state) {
  cv::setNumThreads(1);
  const int age = static_cast<int>(state.range(0));
  detslam::MaskPropagationOptions propagation;
  propagation.flow_scale = static_cast<int>(state.range(1));
  constexpr int kFrames = 8;  // distinct images, reused in turn
  std::vector<cv::Mat> frames;
  std::vector<std::vector<detslam::Instance>> people;
  for (int i = 0; i < kFrames; ++i) {
    frames.push_back(Frame(4 * i));
    std::vector<detslam::Instance> found;
    for (int shift : {0, 200}) {
      detslam::Instance person;
      person.class_name = "person";
      person.mask = PersonMask(4 * i + shift - 100);
      person.box = cv::boundingRect(person.mask);
      found.push_back(person);
    }
    people.push_back(found);
  }
  detslam::MaskCarrier carrier(propagation);
  int64_t index = 0;
  for (auto _ : state) {
    const int i = static_cast<int>(index % kFrames);
    if (index % age == 0) {
      state.PauseTiming();
      carrier.Publish(index, frames[static_cast<size_t>(i)], people[static_cast<size_t>(i)]);
      state.ResumeTiming();
    }
    ++index;
    auto carried = carrier.Carry(index, frames[static_cast<size_t>(index % kFrames)]);
    benchmark::DoNotOptimize(carried);
  }
}
BENCHMARK(BM_MaskCarry)
    ->ArgsProduct({{1, 3, 6}, {1, 2, 4}})
    ->Unit(benchmark::kMillisecond);

// What the Det-SLAM stage does with a frame's masks before ORB extraction: two people's regions
// (mask dilated by the ORB patch radius, the paper's depth interval over the dominant depth mode)
// and the ignore mask ORB skips. Depth: the room at 2.5-4 m, the people at about 1.4 and 1.9 m,
// 5 % of pixels missing.
void BM_RegionsAndIgnoreMask(benchmark::State& state) {
  cv::setNumThreads(1);
  cv::Mat depth(480, 640, CV_32FC1);
  cv::RNG rng(5);
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) depth.at<float>(y, x) = 2.5f + 1.5f * x / depth.cols;
  }
  std::vector<detslam::Instance> people;
  for (int shift : {-100, 100}) {
    detslam::Instance person;
    person.class_name = "person";
    person.mask = PersonMask(shift);
    person.box = cv::boundingRect(person.mask);
    depth.setTo(shift < 0 ? 1.4 : 1.9, person.mask);
    people.push_back(person);
  }
  cv::Mat noise(depth.size(), CV_32FC1);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 0.01);
  depth += noise;
  cv::Mat missing(depth.size(), CV_32FC1);
  rng.fill(missing, cv::RNG::UNIFORM, 0.0, 1.0);
  depth.setTo(0.0f, missing < 0.05f);
  const detslam::DynamicFilterOptions options;
  for (auto _ : state) {
    const auto regions = detslam::DynamicRegions::Build(people, depth, depth.size(), options);
    cv::Mat ignore = regions.IgnoreMask(depth);
    benchmark::DoNotOptimize(ignore.data);
  }
}
BENCHMARK(BM_RegionsAndIgnoreMask)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) { return detslam::bench::RunKernelBenchmarks(argc, argv); }
