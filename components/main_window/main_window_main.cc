// caliper-main: the Main Window, a plain Qt client of the Model (no component lifecycle).
//
//   caliper-main [--nameservice corbaname::HOST:PORT] [--model INSTANCE] [MODEL_FILE]
#include <QApplication>
#include <QFileInfo>
#include <iostream>
#include <string>
#include <vector>

#include "caliper/rtc.hh"
#include "main_window.h"
#include "model_link.h"

int main(int argc, char** argv) {
  QApplication app(argc, argv);
  caliper::main_window::ModelLink::Options options;
  std::string model_file;
  const QStringList args = QApplication::arguments();
  for (int i = 1; i < args.size(); ++i) {
    const std::string a = args[i].toStdString();
    if ((a == "--nameservice" || a == "--model") && i + 1 < args.size()) {
      (a == "--nameservice" ? options.nameservice : options.instance) = args[++i].toStdString();
    } else if (a == "--help" || a == "-h") {
      std::cout << "usage: caliper-main [--nameservice corbaname::HOST:PORT] [--model INSTANCE] "
                   "[MODEL_FILE]\n";
      return 0;
    } else if (!a.empty() && a[0] != '-') {
      model_file = a;
    } else {
      std::cerr << "caliper-main: unknown option '" << a << "'\n";
      return 2;
    }
  }

  std::vector<std::string> orb_args = {"caliper-main", "-ORBendPoint", "giop:tcp:127.0.0.1:"};
  std::vector<char*> orb_argv;
  for (auto& a : orb_args) orb_argv.push_back(a.data());
  int orb_argc = static_cast<int>(orb_argv.size());
  CORBA::ORB_var orb = CORBA::ORB_init(orb_argc, orb_argv.data());

  int status = 0;
  {
    auto link = std::make_unique<caliper::main_window::ModelLink>(options);
    if (!model_file.empty()) {
      const QString path = QFileInfo(QString::fromStdString(model_file)).absoluteFilePath();
      link->LoadScene(path.toStdString());
    }
    caliper::main_window::MainWindow window(std::move(link));
    window.show();
    status = QApplication::exec();
  }
  orb->destroy();
  return status;
}
