#pragma once
// ReduceLROnPlateau with PyTorch's exact semantics (torch.optim.lr_scheduler, mode 'min'),
// stepped once per epoch on the validation loss:
//   better   <=> current < best * (1 - threshold)   (threshold_mode 'rel')
//                current < best - threshold          (threshold_mode 'abs')
//   a better epoch resets num_bad_epochs, a worse one increments it; during cooldown the
//   counter is decremented and bad epochs are ignored; when num_bad_epochs > patience the
//   rate becomes max(lr * factor, min_lr) (only if that changes it by more than eps = 1e-8),
//   the cooldown starts and the counter resets.
#include <algorithm>
#include <limits>

namespace yarnhom {

struct PlateauParams {
  double factor = 0.5;
  int patience = 80;
  double threshold = 0.01;
  bool relative = true;  // threshold_mode 'rel' (else 'abs')
  int cooldown = 0;
  double min_lr = 0.0;
  double eps = 1e-8;
};

class ReduceLROnPlateau {
 public:
  explicit ReduceLROnPlateau(double lr, PlateauParams p = {}) : p_(p), lr_(lr) {}

  // Returns the learning rate for the next epoch.
  double step(double current) {
    if (better(current)) {
      best_ = current;
      bad_ = 0;
    } else {
      ++bad_;
    }
    if (cooldown_counter_ > 0) {
      --cooldown_counter_;
      bad_ = 0;
    }
    if (bad_ > p_.patience) {
      const double next = std::max(lr_ * p_.factor, p_.min_lr);
      if (lr_ - next > p_.eps) lr_ = next;
      cooldown_counter_ = p_.cooldown;
      bad_ = 0;
    }
    return lr_;
  }

  double lr() const { return lr_; }
  double best() const { return best_; }
  int num_bad_epochs() const { return bad_; }

 private:
  bool better(double a) const {
    // NaN is never better (comparisons with NaN are false), as in PyTorch.
    return p_.relative ? a < best_ * (1.0 - p_.threshold) : a < best_ - p_.threshold;
  }
  PlateauParams p_;
  double lr_;
  double best_ = std::numeric_limits<double>::infinity();
  int bad_ = 0, cooldown_counter_ = 0;
};

}  // namespace yarnhom
