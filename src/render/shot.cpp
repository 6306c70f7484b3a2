// A shot's frames over its workers (see shot.h).
#include "render/shot.h"

#include "render/method.h"
#include "render/pass_names.h"
#include "render/renderer.h"
#include "render/view_targets.h"
#include "vk/error.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace snell::render {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// How often a thread waiting for frames looks at ShotIo::stop (a signal cannot wake it).
constexpr auto kStopPoll = std::chrono::milliseconds(50);

// What the calling thread and the workers share, under one mutex.
struct Queue {
  std::mutex mutex;
  std::condition_variable changed;
  std::deque<ShotFrame> pending;   ///< fed, not yet taken
  std::deque<ShotImage> finished;  ///< drawn, for the calling thread
  size_t busy = 0;                 ///< frames being drawn
  size_t working = 0;              ///< workers that may still draw
  bool exhausted = false;          ///< ShotIo::next has no more
  bool failed = false;             ///< an error every device would meet: everyone stops
};

class Worker {
 public:
  Worker(const scene::Scene& scene, const ShotSettings& settings, const ShotIo& io, Queue& queue, size_t id,
         ShotDevice device, vk::ContextDesc desc)
      : scene_(scene), settings_(settings), io_(io), queue_(queue), id_(id), device_(std::move(device)),
        desc_(std::move(desc)) {}

  // Never throws: what went wrong stays in error().
  void run() {
    vk::setFaultWorker(int(id_));
    const auto start = Clock::now();
    try {
      open();
      report_.loadSeconds = secondsSince(start);
      while (std::optional<ShotFrame> frame = take()) {
        ShotImage image;
        try {
          image = draw(*frame);
        } catch (const vk::VulkanError& e) {
          giveBack(std::move(*frame), e.result() == VK_ERROR_DEVICE_LOST);
          throw;
        } catch (...) {
          giveBack(std::move(*frame), false);
          throw;
        }
        image.frame = std::move(*frame);
        hand(std::move(image));
      }
    } catch (const vk::VulkanError& e) {
      error_ = std::current_exception();
      lost_ = e.result() == VK_ERROR_DEVICE_LOST;
      report_.lost = e.what();
      if (!lost_) fail();
    } catch (...) {
      error_ = std::current_exception();
      fail();
    }
    if (context_) report_.validationMessages = context_->validationMessageCount();
    if (choice_) report_.method = choice_->describe();
    std::lock_guard lock(queue_.mutex);
    --queue_.working;
    queue_.changed.notify_all();
  }

  ShotWorker& report() { return report_; }
  std::exception_ptr error() const { return error_; }
  bool lostDevice() const { return lost_; }

 private:
  bool stopped() const { return io_.stop && *io_.stop; }

  void fail() {
    std::lock_guard lock(queue_.mutex);
    queue_.failed = true;
    queue_.changed.notify_all();
  }

  void open() {
    std::optional<Method> named = methodFromName(settings_.method);
    vk::ContextDesc desc = desc_;
    if (!device_.override.empty()) desc.deviceOverride = device_.override;
    desc.driverRayTracing = desc.driverRayTracing || settings_.method == "auto" || (named && needsDriverRayTracing(*named));
    context_ = vk::Context::create(desc);
    report_.device = context_->facts().name;
    report_.why = device_.why.empty() ? context_->deviceWhy() : device_.why;
    choice_.emplace(settings_.method, context_->caps().driverRayTracing, settings_.viewport, settings_.frames);
    checkImageSize(*context_, settings_.frame.width, settings_.frame.height);
    RendererOptions options;
    options.passTimes = settings_.passTimes || choice_->isAuto();  // timestamps only where someone reads them
    options.independentFrames = true;  // a frame's pixels are the same whichever worker, chunk or retry draws it
    options.keepVertices = settings_.keepVertices;
    // Which items exist does not change with time: any pose builds the renderer.
    renderer_ = std::make_unique<Renderer>(*context_, scene_, scene::evaluate(scene_, settings_.bakeTime), options);
    if (io_.opened) io_.opened(id_, report_);
    if (choice_->next() == Method::RefractionMap) {
      // The trace bakes the map once, and every frame reads it as the scene moves on.
      if (!settings_.view) throw std::invalid_argument("shot: refraction-map bakes its map from ShotSettings::view");
      scene::Pose pose = scene::evaluate(scene_, settings_.bakeTime);
      std::optional<RefractionBake> bake = renderer_->keepRefractionMap(pose, frameSettings(settings_.view(pose)));
      if (bake && io_.baked) io_.baked(id_, *bake);
    }
  }

  FrameSettings frameSettings(const scene::View& view) const {
    FrameSettings s = settings_.frame;
    s.view = view;
    return s;
  }

  // The next frame to draw; none once there are no more, or the shot stops.
  std::optional<ShotFrame> take() {
    std::unique_lock lock(queue_.mutex);
    while (!stopped() && !queue_.failed && queue_.pending.empty() && !queue_.exhausted) {
      queue_.changed.wait_for(lock, kStopPoll);
    }
    if (stopped() || queue_.failed || queue_.pending.empty()) return std::nullopt;
    ShotFrame frame = std::move(queue_.pending.front());
    queue_.pending.pop_front();
    ++queue_.busy;
    queue_.changed.notify_all();  // room for the calling thread to feed another
    return frame;
  }

  // A frame this worker will not finish: for another worker where its device was lost.
  void giveBack(ShotFrame&& frame, bool again) {
    std::lock_guard lock(queue_.mutex);
    if (again) queue_.pending.push_front(std::move(frame));
    --queue_.busy;
    queue_.changed.notify_all();
  }

  ShotImage draw(const ShotFrame& frame) {
    const auto start = Clock::now();
    ShotImage image;
    image.worker = id_;
    image.device = report_.device;
    image.why = report_.why;
    image.facts = &context_->facts();
    image.pose = scene::evaluate(scene_, frame.seconds);
    for (const auto& [item, world] : frame.transforms) image.pose.items.at(item).world = world;
    for (const ShotFrame::Vertices& v : frame.vertices) {
      KeptVertices kept = renderer_->keptVertices(v.shape);
      if (v.positions.size() != size_t(kept.count) * 3 || v.normals.size() != v.positions.size()) {
        throw std::invalid_argument("shot: frame " + std::to_string(frame.number) + " gives shape " +
                                    std::to_string(v.shape) + " " + std::to_string(v.positions.size()) +
                                    " position floats for its " + std::to_string(kept.count) + " vertices");
      }
      std::memcpy(kept.positions, v.positions.data(), v.positions.size() * sizeof(float));
      std::memcpy(kept.normals, v.normals.data(), v.normals.size() * sizeof(float));
      renderer_->markDirty(v.shape);
    }
    if (frame.view) {
      image.view = *frame.view;
    } else if (settings_.view) {
      image.view = settings_.view(image.pose);
    } else {
      throw std::invalid_argument("shot: frame " + std::to_string(frame.number) + " has no camera");
    }
    const Method method = choice_->next();
    ViewRequest view = choice_->view(method, frameSettings(image.view), settings_.raster);
    view.aov = view.aov || (settings_.aov && view.output == ViewOutput::Trace && !view.driverTrace);
    image.method = methodName(method);
    image.composite = view.output == ViewOutput::Composite;
    FrameRequest request;
    request.pose = &image.pose;
    request.views.push_back(std::move(view));
    request.readbacks.push_back({.view = 0, .half = true, .trace = !image.composite});
    const auto waitStart = Clock::now();
    const FrameResult& result = renderer_->wait(renderer_->submit(request));
    report_.gpuWaitSeconds += secondsSince(waitStart);
    for (const vk::PassTime& p : result.passes) report_.treeMs += isTreePass(p.name) ? p.milliseconds : 0.0;
    choice_->note(method, result.passes);
    image.methodLine = choice_->describe();
    image.pixels = result.views.at(0);
    image.stats = result.stats;
    image.passes = result.passes;
    image.drawSeconds = secondsSince(start);
    return image;
  }

  // A drawn frame to its sink, unless the shot stopped meanwhile (then it is dropped).
  void hand(ShotImage&& image) {
    if (io_.sinkOnWorkers && !stopped()) {
      const auto start = Clock::now();
      io_.done(std::move(image));
      report_.sinkSeconds += secondsSince(start);
      ++report_.frames;
    }
    std::lock_guard lock(queue_.mutex);
    if (!io_.sinkOnWorkers && !stopped()) queue_.finished.push_back(std::move(image));
    --queue_.busy;
    queue_.changed.notify_all();
  }

  const scene::Scene& scene_;
  const ShotSettings& settings_;
  const ShotIo& io_;
  Queue& queue_;
  size_t id_;
  ShotDevice device_;
  vk::ContextDesc desc_;
  std::unique_ptr<vk::Context> context_;
  std::unique_ptr<Renderer> renderer_;
  std::optional<MethodChoice> choice_;
  ShotWorker report_;
  std::exception_ptr error_;
  bool lost_ = false;
};

// The calling thread's part: feeds frames while the queue has room, and hands
// the finished ones over, until every frame is drawn or the shot ends.
// Returns whether every frame was drawn and handed over.
bool pump(const ShotIo& io, Queue& q, std::vector<std::unique_ptr<Worker>>& workers, ShotReport& report) {
  const size_t room = 2 * workers.size();
  auto stopped = [&] { return io.stop && *io.stop; };
  std::unique_lock lock(q.mutex);
  for (;;) {
    while (!q.finished.empty() && !stopped()) {
      ShotImage image = std::move(q.finished.front());
      q.finished.pop_front();
      lock.unlock();
      const size_t worker = image.worker;
      const auto start = Clock::now();
      io.done(std::move(image));
      lock.lock();
      workers[worker]->report().sinkSeconds += secondsSince(start);
      ++workers[worker]->report().frames;
      ++report.frames;
    }
    if (stopped() || q.failed) return false;
    if (q.exhausted && q.pending.empty() && q.busy == 0 && q.finished.empty()) return true;
    if (q.working == 0) return false;  // every device lost with frames left
    if (!q.exhausted && q.pending.size() < room) {
      lock.unlock();
      std::optional<ShotFrame> frame = io.next();
      lock.lock();
      if (frame) {
        q.pending.push_back(std::move(*frame));
      } else {
        q.exhausted = true;
      }
      q.changed.notify_all();
      continue;
    }
    q.changed.wait_for(lock, kStopPoll);
  }
}

}  // namespace

std::vector<ShotDevice> shotDevices(const std::string& list, const vk::DeviceEnvironment& environment,
                                    const std::string& single) {
  if (list.empty()) return {{single, ""}};
  std::string why;
  std::vector<ShotDevice> devices;
  for (uint32_t index : vk::devicesForList(list, environment, why)) devices.push_back({std::to_string(index), why});
  return devices;
}

ShotReport renderShot(const scene::Scene& scene, const ShotSettings& settings, const vk::ContextDesc& context,
                      const std::vector<ShotDevice>& devices, const ShotIo& io) {
  if (devices.empty()) throw std::invalid_argument("shot: no device to draw on");
  if (!io.next || !io.done) throw std::invalid_argument("shot: ShotIo needs next and done");
  const auto start = Clock::now();
  ShotSettings shared = settings;
  if (devices.size() > 1 && shared.method == "auto") shared.method = "trace";
  Queue queue;
  queue.working = devices.size();
  std::vector<std::unique_ptr<Worker>> workers;
  for (size_t k = 0; k < devices.size(); ++k) {
    workers.push_back(std::make_unique<Worker>(scene, shared, io, queue, k, devices[k], context));
  }
  ShotReport report;
  std::exception_ptr callerError;
  bool complete = false;
  {
    std::vector<std::jthread> threads;
    for (auto& w : workers) threads.emplace_back([&worker = *w] { worker.run(); });
    try {
      complete = pump(io, queue, workers, report);
    } catch (...) {
      callerError = std::current_exception();  // the caller's own next or done threw: stop everyone first
    }
    std::lock_guard lock(queue.mutex);
    queue.exhausted = true;
    queue.failed = queue.failed || callerError;
    queue.changed.notify_all();
  }
  for (auto& w : workers) {
    report.workers.push_back(w->report());
    if (io.sinkOnWorkers) report.frames += w->report().frames;
  }
  report.seconds = secondsSince(start);
  report.stopped = io.stop && *io.stop;
  if (callerError) std::rethrow_exception(callerError);
  if (report.stopped) return report;
  // A failure every device would meet (a file that cannot be written): the first one's error.
  for (auto& w : workers) {
    if (w->error() && !w->lostDevice()) std::rethrow_exception(w->error());
  }
  // Lost devices: fatal only when their frames found no other device.
  for (auto& w : workers) {
    if (w->lostDevice() && !complete) std::rethrow_exception(w->error());
  }
  return report;
}

bool isTreePass(const std::string& name) {
  return name == pass::kBlasBuild || name == pass::kBlasRefit || name == pass::kTlas || name == pass::kSortHistogram ||
         name == pass::kSortScan || name == pass::kSortScatter;
}

}  // namespace snell::render
