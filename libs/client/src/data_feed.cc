#include "caliper/client/data_feed.h"

namespace caliper::client {

namespace D = ::Caliper::Daq;
namespace S = ::Caliper::Scene;

// Receives the subscription's batches on ORB threads and hands them to the callback.
class DataFeed::Consumer : public virtual POA_Caliper::Daq::DataConsumer {
 public:
  explicit Consumer(OnBatch on_batch) : on_batch_(std::move(on_batch)) {}

  void on_samples(const D::SampleBatch& in) override {
    std::lock_guard<std::mutex> lock(mutex);
    if (closed) return;
    ++batches;
    Batch b;
    b.number = in.batch;
    for (CORBA::ULong i = 0; i < in.stale_ids.length(); ++i) {
      b.stale_ids.emplace_back(in.stale_ids[i].in());
      stale.insert(b.stale_ids.back());
    }
    b.values_per_sample = in.values_per_sample;
    b.count = in.times.length();
    // a batch whose data is short of its times is cut to the whole samples it holds
    if (b.values_per_sample > 0 && in.data.length() < b.count * b.values_per_sample)
      b.count = in.data.length() / b.values_per_sample;
    b.times = in.times.get_buffer();
    b.data = in.data.get_buffer();
    on_batch_(b);
  }

  std::mutex mutex;  // guards the fields below and what the callback touches
  uint64_t batches = 0;
  std::set<std::string> stale;
  bool closed = false;

 private:
  OnBatch on_batch_;
};

DataFeed::DataFeed(Session& session, const ModelRef& model, const std::vector<std::string>& ids,
                   uint32_t every_n_steps, bool lossless, OnBatch on_batch)
    : model_(model) {
  model_.model = ::Caliper::Simulation::Model::_duplicate(model.model);
  poa_ = session.RootPoa();
  consumer_ = new Consumer(std::move(on_batch));
  owner_ = consumer_;
  oid_ = poa_->activate_object(consumer_);
  CORBA::Object_var ref = poa_->id_to_reference(oid_);
  D::DataConsumer_var consumer_ref = D::DataConsumer::_narrow(ref);
  S::StringSeq seq;
  seq.length(static_cast<CORBA::ULong>(ids.size()));
  for (CORBA::ULong i = 0; i < seq.length(); ++i) seq[i] = ids[i].c_str();
  try {
    subscription_ = Call(model_, [&] {
      return lossless ? model_.model->subscribe_lossless(seq, every_n_steps, consumer_ref)
                      : model_.model->subscribe(seq, every_n_steps, consumer_ref);
    });
  } catch (...) {
    closed_ = true;
    poa_->deactivate_object(oid_);
    throw;
  }
}

DataFeed::~DataFeed() {
  try {
    Close();
  } catch (...) {
  }
}

D::SubscriptionStatus DataFeed::Status() {
  try {
    return model_.model->subscription_status(subscription_);
  } catch (const D::UnknownId& e) {
    throw UnknownIdError(e.reason.in(), e.id.in());  // the Model's own words: why it ended it
  } catch (const CORBA::SystemException& e) {
    throw ConnectionError(Session::Unreachable(model_.path, e), model_.path);
  }
}

void DataFeed::Close() {
  if (closed_) return;
  closed_ = true;
  {
    std::lock_guard<std::mutex> lock(consumer_->mutex);
    consumer_->closed = true;
  }
  try {
    model_.model->unsubscribe(subscription_);
  } catch (const CORBA::Exception&) {
    // gone already: it sends nothing more either way
  }
  poa_->deactivate_object(oid_);
}

std::mutex& DataFeed::mutex() { return consumer_->mutex; }
uint64_t DataFeed::batches() const { return consumer_->batches; }
const std::set<std::string>& DataFeed::stale() const { return consumer_->stale; }

}  // namespace caliper::client
